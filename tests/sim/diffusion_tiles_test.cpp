// Eq. 25's sum in tiles of eight particles (sim/DiffusionKernels.h) has the bits of the loop over
// each particle's living bonds in order, at every vector width (ctest's kernels.* run this at
// each), and follows the bonds as they break.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "sim/DamageState.h"
#include "sim/Diffusion.h"
#include "sim/Random.h"

using namespace rend::sim;

namespace {

/// A hexagonal sheet whose particle count is not a multiple of 8, bonds within 2.5 dx: the
/// edges' particles have fewer bonds than the interior's, so tiles there carry pads.
struct Sheet {
    Sheet() {
        params.sheet.size = {0.31, 0.17};
        params.sheet.dx = 0.01;
        params.sheet.horizonFactor = 2.5;
        params.material.density = 5000.0, params.material.capacity = 1.0;
        params.material.conductivity = 50.0;
        lattice = generateLattice(params.sheet);
        bonds = buildBondFamilies(lattice.positions, 2.5 * params.sheet.dx);
        volumes.assign(lattice.positions.size(), lattice.particleArea * params.sheet.thickness);
    }
    MembraneParams params;
    Lattice lattice;
    BondFamilies bonds;
    std::vector<double> volumes;
};

std::vector<double> naiveStep(const BondFamilies& bonds, const std::vector<double>& rate,
                              const std::vector<std::uint8_t>& alive,
                              const std::vector<double>& theta, double dt) {
    std::vector<double> next(theta.size());
    for (int i = 0; i < bonds.particleCount(); ++i) {
        double flux = 0.0;
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b)
            if (alive[b]) flux += rate[b] * (theta[bonds.partners[b]] - theta[i]);
        next[i] = theta[i] + dt * flux;
    }
    return next;
}

TEST(DiffusionTiles, SumEachParticlesLivingBondsInOrder) {
    const Sheet sheet;
    const BondFamilies& bonds = sheet.bonds;
    const int n = bonds.particleCount();
    ASSERT_NE(n % DiffusionTiles::kTile, 0);
    std::vector<double> rate(bonds.directedCount()), theta(n);
    std::vector<std::uint8_t> alive(bonds.directedCount(), 1);
    for (std::size_t b = 0; b < rate.size(); ++b) rate[b] = 10.0 * uniformFromHash(1, b);
    for (std::size_t b = 0; b < alive.size(); b += 13) alive[b] = 0;
    for (int i = 0; i < n; ++i) theta[i] = 1e3 * (uniformFromHash(2, i) - 0.3);
    DiffusionTiles tiles = DiffusionTiles::build(bonds, rate);
    tiles.refresh(alive.data(), 1);
    const double dt = 1e-3;
    std::vector<double> next(n, -1.0);
    const int whole = n / DiffusionTiles::kTile;
    diffuseTiles(tiles, theta.data(), next.data(), dt, 0, whole);
    for (int i = DiffusionTiles::kTile * whole; i < n; ++i)
        diffuseParticle(tiles, theta.data(), next.data(), dt, i);
    const std::vector<double> expected = naiveStep(bonds, rate, alive, theta, dt);
    EXPECT_EQ(std::memcmp(next.data(), expected.data(), n * sizeof(double)), 0);
    int differ = 0;
    for (int i = 0; i < n; ++i) differ += next[i] != expected[i];
    EXPECT_EQ(differ, 0) << "of " << n;
}

// A diffusion that stepped before some bonds broke steps afterwards as one built on the broken
// bonds does: its copy of which bonds live follows DamageState::version().
TEST(DiffusionTiles, FollowTheBondsAsTheyBreak) {
    const Sheet sheet;
    const int n = sheet.bonds.particleCount();
    DamageState damage(sheet.bonds, sheet.lattice.triangles);
    Diffusion early(sheet.params, sheet.lattice.positions, sheet.bonds, sheet.volumes);
    std::vector<double> theta(n);
    for (int i = 0; i < n; ++i) theta[i] = uniformFromHash(3, i);
    const double dt = 0.5 * early.stableTimeStep();
    std::vector<double> a = theta;
    early.advance(a, damage.bondAlive(), damage.version(), 0.0, dt);
    EXPECT_NE(a, theta);
    for (const double value : a) ASSERT_TRUE(std::isfinite(value));
    for (int b = 0; b < int(sheet.bonds.directedCount()); b += 7) damage.breakBond(b);
    Diffusion late(sheet.params, sheet.lattice.positions, sheet.bonds, sheet.volumes);
    std::vector<double> b = a;
    early.advance(a, damage.bondAlive(), damage.version(), dt, dt);
    late.advance(b, damage.bondAlive(), damage.version(), dt, dt);
    EXPECT_EQ(a, b);
}

}  // namespace
