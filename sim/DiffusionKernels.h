#pragma once
// Eq. 25's sum over a particle's living bonds, rate x (theta_j - theta_i) in its bonds' order,
// for eight particles at once (a tile, sim/PeridynamicBonds.h's order): the k-th bond of the
// tile's particles side by side, so that on a regular lattice the partners' theta load as one
// run of consecutive particles. Each lane adds the same terms in the same order as the scalar
// loop (Diffusion::step), skipping the dead bonds and the pads by a mask: the same bits.

#include <cstdint>
#include <vector>

#include "sim/Bonds.h"

namespace rend::sim {

/// The bonds of a sheet in tiles of kTile particles.
struct DiffusionTiles {
    static constexpr int kTile = 8;
    std::vector<int> tileBegin;        ///< per tile, and one past the last: its first slot
    std::vector<int> partner;          ///< per slot (tileBegin + kTile k + lane): j, or i for a pad
    std::vector<int> bond;             ///< per slot: the directed bond, or -1 for a pad
    std::vector<double> rate;          ///< per slot: the bond's rate, 0 for a pad
    std::vector<std::uint8_t> living;  ///< per slot: the bond is alive (refresh())
    std::uint64_t livingVersion = ~std::uint64_t(0);

    /// The tiles of `bonds`, with `rate` per directed bond.
    static DiffusionTiles build(const BondFamilies& bonds, const std::vector<double>& rate);
    /// Copies `alive` (per directed bond) into `living` when `version` has moved.
    void refresh(const std::uint8_t* alive, std::uint64_t version);
};

/// next[i] = theta[i] + dt sum over living bonds of rate (theta_j - theta_i), particle i alone.
void diffuseParticle(const DiffusionTiles& tiles, const double* theta, double* next, double dt,
                     int i);

/// next[i] = theta[i] + dt sum over living bonds of rate (theta_j - theta_i), for the particles
/// of tiles [firstTile, lastTile) (all eight of each).
void diffuseTiles(const DiffusionTiles& tiles, const double* theta, double* next, double dt,
                  int firstTile, int lastTile);

}  // namespace rend::sim
