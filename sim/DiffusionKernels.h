#pragma once
// Eq. 25's sum over a particle's living bonds, rate x (theta_j - theta_i) in its bonds' order,
// for eight particles at once (a tile, sim/PeridynamicBonds.h's order): the k-th bond of the
// tile's particles side by side, so that on a regular lattice the partners' theta load as one
// run of consecutive particles. Each lane adds the same terms in the same order as the scalar
// loop (Diffusion::step), skipping the dead bonds and the pads by a mask: the same bits.

#include <cstdint>
#include <optional>
#include <vector>

#include "sim/Bonds.h"
#include "sim/DamageState.h"
#include "sim/StepKernels.h"

namespace rend::sim {

/// The bonds of a sheet in tiles of kTile particles.
struct DiffusionTiles {
    static constexpr int kTile = 8;
    std::vector<int> tileBegin;  ///< per tile, and one past the last: its first slot
    std::vector<int> partner;    ///< per slot (tileBegin + kTile k + lane): j, or i for a pad
    std::vector<int> bond;       ///< per slot: the directed bond, or -1 for a pad
    std::vector<double> rate;    ///< per slot: the bond's rate, 0 for a pad
    /// Per row of kTile slots (from a multiple of kTile): lane 0's partner where the row's
    /// partners are consecutive, else -1; and where its rates (the pads' aside) are one value,
    /// that class c >= 0 of classRate; where each is its class's plus whole steps of
    /// classUnit (rateSteps, sim/RowSteps.h), kSteppedRate - c; else -1. On a regular lattice
    /// the eight-lane sums then read an int and a byte or two per slot where they read thirteen
    /// (10^6 particles stream them from memory every step).
    std::vector<int> rowRun, rowClass;
    std::vector<double> classRate, classUnit;
    std::vector<std::uint16_t> rateSteps;
    static constexpr int kSteppedRate = -2;
    /// Per tile: its number of rows (up to 255) where each is a run with one rate (a regular
    /// lattice's interior), whose sums are straight code for 6, 8 or 12 rows (hexagonal,
    /// square, square of horizon 2.2) and a plain loop for the others (the AVX-512 sums' for 8
    /// rows only); else 0.
    std::vector<std::uint8_t> plainTile;
    /// Per row, bit l: slot kTile row + l's bond lives (refresh()); 0 for a pad.
    std::vector<std::uint8_t> livingRows;
    std::uint64_t livingVersion = ~std::uint64_t(0);

    /// The tiles of `bonds`, with `rate` per directed bond.
    static DiffusionTiles build(const BondFamilies& bonds, const std::vector<double>& rate);
    /// Copies `alive` (per directed bond) into `livingRows` when `version` has moved.
    void refresh(const std::uint8_t* alive, std::uint64_t version);
    /// The same from `damage`: where only breaks happened since livingVersion, their slots'
    /// bits alone (DamageState::breaksSince).
    void refresh(const DamageState& damage);
    std::vector<int> offsets;  ///< the bonds' BondFamilies::offsets (a bond's particle)
    /// Whether slot u's bond lives (as of refresh()).
    bool living(int u) const { return (livingRows[u / kTile] >> (u % kTile)) & 1u; }
    /// How many rows are runs, and how many have a class (exact or stepped).
    int runRows() const;
    int classedRows() const;

private:
    void setUpRows();
};

/// next[i] = theta[i] + dt sum over living bonds of rate (theta_j - theta_i), particle i alone.
void diffuseParticle(const DiffusionTiles& tiles, const double* theta, double* next, double dt,
                     int i);

/// What diffuseTiles() may measure of the values it writes, as the functions named below would
/// over the same particles (the same values).
struct DiffusionMeasures {
    double largestChange = 0.0;  ///< sim/PairKernels.h's largestChange(theta, next)
    GuardSums theta;             ///< sim/StepKernels.h's guardThetaSums(next)
};

/// next[i] = theta[i] + dt sum over living bonds of rate (theta_j - theta_i), for the particles
/// of tiles [firstTile, lastTile) (all eight of each). With `around`, the eight-lane sums of
/// the plain tiles store around the caches where next lies on 64-byte lines (the same values);
/// by default, where the sheet is larger than the caches (sim/PairSums.h's streamsForces()).
/// With `measures`, their measures of those particles: eight lanes wide from the sums'
/// registers, else by reading next back.
void diffuseTiles(const DiffusionTiles& tiles, const double* theta, double* next, double dt,
                  int firstTile, int lastTile, std::optional<bool> around = std::nullopt,
                  DiffusionMeasures* measures = nullptr);

}  // namespace rend::sim
