#pragma once
// The vectorised first pass of the force loop of every bond law (eqs. 18-20 with eqs. 10,
// 27-28, the diffusion's strain and weakening, the power law's look-ahead and the elastoplastic
// history): each pair's force on its smaller index, from structure-of-arrays inputs, for a range
// of pairs. sim/PairSums.h sums the pair forces per particle. Eight pairs at a time
// with AVX-512 where the CPU has it, else eight as two AVX2 vectors, else one at a time
// (sim/PairKernelSimd.inc is the one kernel for both); all use only +, -, *, / and sqrt, and
// fused multiply-adds only in eq. 20's e^x (sim/LawExp.h, at every width), so their bits are the
// same. The width is sim/StepKernels.h's simdWidth().

#include <cstddef>
#include <cstdint>
#include <limits>

#include "sim/BondLaw.h"

namespace rend::sim {

/// Pairs per tile of the pair order (sim/PeridynamicBonds.h): the kernels take whole tiles.
inline constexpr int kPairTile = 8;

struct LinearPairInput {
    const int* first = nullptr;   ///< per pair: the smaller index i
    const int* second = nullptr;  ///< per pair: j
    const double* restLength = nullptr;
    const double* scale = nullptr;  ///< the bond scale (sim/BondLaw.h)
    const double* limit = nullptr;  ///< eta_c times the map's factor; null: unbreakable
    const double* x = nullptr;      ///< positions, x y z per particle
    const double* theta = nullptr;  ///< null: no diffusion
    double c = 0.0;                 ///< micromodulus
    double expansion = 0.0;         ///< alpha
    double stiffnessLoss = 0.0;     ///< of sim/Material.h's degradation()
    double strengthLoss = 0.0;
    /// The law (the power law with a whole exponent n of 2, 3 or 4, no maps of its parameters
    /// or of the yield strain), with the constants of the power and elastoplastic laws copied
    /// below (the kernels' own copy of the input keeps them in registers: read through `law`,
    /// every store to `held` read them again).
    const BondLaw* law = nullptr;
    double powerC = 0.0, powerCStar = 0.0, powerN = 4.0;
    double yieldStrain = 0.0, softening = 0.0;
    /// advance(): the power law's look-ahead (needs v, dt), the elastoplastic history's update.
    bool update = false;
    /// The largest look-ahead tangent over c the caller already found (at least 1): lanes that
    /// cannot exceed it are not looked at, and the answer is at least it.
    double stiffestKnown = 1.0;
    const double* v = nullptr;
    double dt = 0.0;
    /// The look-ahead counts only the pairs whose first end is at or past it: this process's
    /// own (a decomposed run computes its ghosts' pairs for its sums, but whether a bond between
    /// two ghosts lives is their owner's to know).
    int ownBegin = 0;
    /// lookAheadSlack() of the particles the pairs reach: a lane with (eta - reach) rest at or
    /// above it cannot stretch back below the look-ahead's reach within dt. With skipFar, a
    /// vector with no compressed lane nearer than that skips the look-ahead (its velocities are
    /// not read), and LinearPairOutput::nearRows counts the others.
    double lookAheadSlack = std::numeric_limits<double>::infinity();
    bool skipFar = false;
    const std::uint8_t* alive = nullptr;  ///< per directed bond
    bool allAlive = false;                ///< no bond has broken: every alive flag is 1
    const int* upper = nullptr;           ///< per pair: its upper copy
    const int* twin = nullptr;            ///< per pair: its lower copy
    /// Per pair (elastoplastic): the largest strain its bond has reached (BondLaw's
    /// PlasticState), moved on by advance() for the living, unbroken bonds.
    double* held = nullptr;
    /// Per kPairTile pairs from a multiple of it, bit k: whether pair k's bond lives; read where
    /// held is moved on and not allAlive.
    const std::uint8_t* livingRows = nullptr;
    /// Per kPairTile pairs from a multiple of it (a vector, or two): where their ends are runs
    /// of consecutive particles, the first of each run (else -1); where their rest lengths,
    /// bond scales and limits are each one value, its class c >= 0 in the tables; where each is
    /// its class's value plus whole steps of its unit (16 bits per pair, restSteps...; the
    /// limits may be the class's value), steppedClass(); else -1. Classed vectors read none of
    /// the per-pair doubles above.
    const int* runFirst = nullptr;
    const int* runSecond = nullptr;
    const int* uniform = nullptr;
    const double *classRest = nullptr, *classScale = nullptr, *classLimit = nullptr;
    const double *classRestUnit = nullptr, *classScaleUnit = nullptr, *classLimitUnit = nullptr;
    const std::uint16_t *restSteps = nullptr, *scaleSteps = nullptr, *limitSteps = nullptr;
    /// How many particles ahead of a tile's first the kernels prefetch x and theta (0: none),
    /// and how many particles x holds; how many pairs held holds (its prefetch stays inside).
    int prefetchAhead = 0, particles = 0, pairs = 0;
};
inline constexpr int kSteppedClass = -2;
/// A stepped row reads steps for its rest lengths and scales, and for its limits only where
/// they are stepped too: on a lattice whose coordinates carry rounding, the rest lengths and
/// the scales (over the rest length) are stepped and the limits one value.
/// LinearPairInput::uniform of such a row of class c is steppedClass(c, whether its limits are
/// stepped); steppedClassOf() gives c back, and limitsStepped() the other.
inline constexpr int kStepsLimit = 1 << 29;
inline constexpr int steppedClass(int c, bool limits) {
    return kSteppedClass - c - (limits ? kStepsLimit : 0);
}
inline constexpr int steppedClassOf(int uniform) {
    return (kSteppedClass - uniform) & (kStepsLimit - 1);
}
inline constexpr bool limitsStepped(int uniform) { return uniform <= kSteppedClass - kStepsLimit; }

/// Where a pair's force lies in its slots. In rows (four or eight lanes wide, sim/PairSums.h's
/// tile sums): rows of kPairTile slots, the x of the row's pairs, then their y, then their z, so
/// that eight lanes store and load them without a transpose. Else x y z 0 per slot (one load per
/// pair for a particle's sum).
inline constexpr int kSlotRow = 3 * kPairTile;
inline std::size_t slotAt(unsigned s, bool rows) {
    return rows ? kSlotRow * std::size_t(s / kPairTile) + s % kPairTile : 4 * std::size_t(s);
}
/// How far apart a slot's x, y and z lie.
inline int slotStride(bool rows) { return rows ? kPairTile : 1; }
/// Whether the slots are in rows: the width is 4 or 8.
bool slotRows();

/// Membrane::failureApproachRate's measure: how fast the pairs loaded past half their critical
/// stretch approach it, ds/dt over the margin left (at least delta eta_c).
struct ApproachRate {
    double critical = 0.0;  ///< eta_c: the membrane's, without maps
    double expansion = 0.0, strengthLoss = 0.0;
    double delta = 0.0;                 ///< time.max_stretch_increment
    const std::uint8_t* pad = nullptr;  ///< per pair: a tile's repeat (not counted)
    int ownBegin = 0, ownEnd = 0;       ///< the pairs counted: their first end in this range
};

struct LinearPairOutput {
    /// Pair u's force on i at slotAt(u - slotBase, rows), or, with rowSlot, x at
    /// rowSlot[u / kPairTile] + u % kPairTile and y, z `stride` and twice that after: zero past
    /// its limit. slotBase is a multiple of kPairTile.
    double* force = nullptr;
    /// Per row of kPairTile pairs (only with a limit): bit u % kPairTile of byte u / kPairTile,
    /// pair u is past its limit. The kernels take rows whole: begin is a multiple of kPairTile.
    std::uint8_t* over = nullptr;
    /// With a limit, where not null: per row, as over, bit u % kPairTile set where pair u may
    /// count in Membrane::failureApproachRate by `approach` (the kernels: exactly where its
    /// screen, loaded past half eta_c, holds; one pair at a time: every pair), for
    /// flaggedApproachRate().
    std::uint8_t* approaching = nullptr;
    const ApproachRate* approach = nullptr;
    int slotBase = 0;
    bool rows = false;  ///< slotRows()
    /// In rows, per row of kPairTile pairs: where its lane 0's x lies (PeridynamicBonds lays a
    /// tile's k-th rows of consecutive tiles side by side, so that a particle's lower copies,
    /// lanes of two tiles' rows, load as one run); null: slotAt(u - slotBase, rows).
    const int* rowSlot = nullptr;
    int stride = kPairTile;
    /// Pair u's x; its y and z slotStep() and twice that after.
    double* slot(int u) const {
        return rowSlot ? force + rowSlot[unsigned(u) / kPairTile] + unsigned(u) % kPairTile
                       : force + slotAt(unsigned(u - slotBase), rows);
    }
    int slotStep() const { return rowSlot ? stride : slotStride(rows); }
    /// With LinearPairInput::skipFar: the vectors with a compressed lane within its
    /// lookAheadSlack of the reach are added to it.
    int* nearRows = nullptr;
    /// Where not null, the power law's update lowers it to the least eta - reach x rest of the
    /// pairs (NaN may be left out; reach: the look-ahead strain below which a pair may raise
    /// the largest tangent, from in.stiffestKnown and rising with it). A pair whose eta falls
    /// by less than this minus the next look-ahead's lookAheadSlack cannot raise it above
    /// in.stiffestKnown (PeridynamicBonds::lookAheadClear).
    double* nearest = nullptr;
};

/// The largest rate over pairs [begin, end) that live (in.alive of their upper copy), are not
/// pads and whose first end is owned; 0 if none. The bits of Membrane's loop over bonds, term by
/// term (in.x, in.v, in.theta, in.restLength or its classes).
double pairApproachRate(const LinearPairInput& in, const ApproachRate& a, int begin, int end);
/// The same over the pairs of [begin, end) whose bit is set in `approaching`
/// (LinearPairOutput::approaching, from the pairs' forces at the same x, theta and flags): the
/// same value, one pair at a time where the pass flagged one.
double flaggedApproachRate(const LinearPairInput& in, const ApproachRate& a,
                           const std::uint8_t* approaching, int begin, int end);

/// The largest |p[k]| of n values, simdWidth() lanes at a time (a NaN may be left out).
double largestMagnitude(const double* p, std::size_t n);

/// dt |v_j - v_i| bounded from the largest |component| of the particles' velocities, above its
/// rounding: dt 2 sqrt(3) (1 + 2^-20) largest (a NaN component left out, as the look-ahead's
/// tests leave a NaN rate out); infinity where that is not finite.
double lookAheadSlack(double largest, double dt);

/// The largest |after[k] - before[k]| of n values, simdWidth() lanes at a time (a NaN may be
/// left out).
double largestChange(const double* before, const double* after, std::size_t n);

/// y[k] = e^x[k] as the elastoplastic kernel computes it, simdWidth() lanes at a time (the bits
/// of sim/LawExp.h's lawExp).
void lawExpLanes(const double* x, double* y, int n);

/// Pairs [begin, end). Dead bonds are computed too: the gather skips them. Returns the power
/// law's largest look-ahead tangent over c among the living, unbroken, compressed pairs (at
/// least 1; 1 without a look-ahead).
double linearPairForces(const LinearPairInput& in, const LinearPairOutput& out, int begin, int end);

}  // namespace rend::sim
