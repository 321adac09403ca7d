#pragma once
// Eq. 26's kick and drift in one pass over a range of particles, eight free particles at a time
// with AVX-512 or four with AVX2 where the CPU has it, else one at a time. All use only +, -, *
// and / (no fused multiply-add), in the order of Membrane::updateVelocity, so their bits are the
// same. The pass also tells whether any free particle ended up not above a floor, so that a
// scene whose only collider is the ground skips the contact pass on the steps nothing touches.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>

namespace rend::sim {

struct KickDrift {
    double* x = nullptr;  ///< x y z per particle
    double* v = nullptr;
    const double* force = nullptr;  ///< x y z per particle from particle forceFirst (below)
    const double* mass = nullptr;
    /// -1 free, -2 pinned, k >= 0 driven by boundary k (Membrane's tags).
    const std::int16_t* constraint = nullptr;
    /// x y z per boundary: the prescribed velocity of its particles at the end of the step.
    std::span<const double> boundaryVelocity;
    double h = 0.0;   ///< the kick
    double dt = 0.0;  ///< the drift
    double gravity[3] = {0.0, 0.0, 0.0};
    double damping = 0.0;
    double floor = -std::numeric_limits<double>::infinity();  ///< the ground's height; -inf: none
    /// Where every particle has the same mass (Membrane::oneMass()), that mass, and `mass` is
    /// not read (a sheet past the caches streams 8 bytes a particle less); 0: per particle.
    double oneMass = 0.0;
    /// Where `force` is the whole force array, 0. Where it is a block a solver kept the forces
    /// of particles from forceFirst in (BlockMotion::move), keptForce is the force array, and
    /// the particles that are not free have theirs copied into it (the blow-up guard reads a
    /// driven particle's).
    int forceFirst = 0;
    double* keptForce = nullptr;
    /// Particle i's force.
    const double* forceOf(int i) const { return force + 3 * (std::ptrdiff_t(i) - forceFirst); }
};

/// Particles [begin, end): v += h (f / m + g - damping v) for the free ones, the pinned at rest,
/// the driven at their boundary's velocity; then x += dt v. Returns whether a free particle's z
/// is not >= k.floor afterwards (NaN counts); false without a floor (k.floor = -inf).
bool kickDrift(const KickDrift& k, int begin, int end);

/// What the blow-up guard (sim/BlowUpGuard.h) reads of a range of particles after a step.
struct GuardInput {
    const double* v = nullptr;  ///< x y z per particle
    const double* force = nullptr;
    const double* mass = nullptr;
    const std::int16_t* constraint = nullptr;
    const double* theta = nullptr;  ///< null: no diffusion
    double limitSquared = 0.0;      ///< the speed limit, squared
    double gravity[3] = {0.0, 0.0, 0.0};
    bool hasGravity = false;
    double oneMass = 0.0;  ///< as KickDrift's: > 0, every particle's mass (`mass` not read)
};

/// Its sums (BlowUpGuard::Sample's): in a fixed order for a given range and width, so the same
/// for any thread count. The scalar loop adds in four chains, of every fourth particle, and AVX2
/// in the same four (the same bits); AVX-512 in more.
struct GuardSums {
    double kinetic = 0.0, boundaryPower = 0.0, gravityPower = 0.0;
    double maxSpeedSquared = 0.0, maxAbsTheta = 0.0;
    int fastest = -1, firstBad = -1;
};

/// Particles [begin, end): the free particles' kinetic energy, |m g . v| and largest speed
/// (the lowest index at it), the driven ones' |f . v|, the largest |theta|, and the lowest index
/// whose speed is not within the limit or whose theta is not finite.
GuardSums guardSums(const GuardInput& g, int begin, int end);
/// Its two halves: the motion's (g.theta unread), and theta's (maxAbsTheta and firstBad only),
/// which addThetaSums() joins into the motion's; guardSums() is the two joined.
GuardSums guardMotionSums(const GuardInput& g, int begin, int end);
GuardSums guardThetaSums(const double* theta, int begin, int end);
void addThetaSums(GuardSums& motion, const GuardSums& theta);
/// kickDrift over [begin, end) (`below` its answer), and guardMotionSums(g, begin, end) of the
/// velocities it leaves: the same bits as the two one after the other, in one pass where both
/// run four lanes wide. g.v must be k.v.
GuardSums kickDriftSampled(const KickDrift& k, const GuardInput& g, int begin, int end,
                           bool& below);

/// Lanes of the vector kernels here and in sim/PairKernels.h: 8 with AVX-512, 4 with AVX2, 1
/// without. REND_SIMD=avx2 or REND_SIMD=scalar in the environment caps it (to compare them; every
/// width gives the same bits).
int simdWidth();

}  // namespace rend::sim
