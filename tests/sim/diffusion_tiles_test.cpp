// Eq. 25's sum in tiles of eight particles (sim/DiffusionKernels.h) has the bits of the loop over
// each particle's living bonds in order, at every vector width (ctest's kernels.* run this at
// each), and follows the bonds as they break.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <tuple>
#include <vector>

#include "sim/DamageState.h"
#include "sim/Diffusion.h"
#include "sim/Random.h"

using namespace rend::sim;

namespace {

/// A sheet whose particle count is not a multiple of 8, hexagonal with bonds within 2.5 dx, or
/// square within 1.5 dx (31 particles a row: a tile in four holds a row's end, as rows of one
/// offset): the edges' particles have fewer bonds than the interior's, so tiles there carry pads.
struct Sheet {
    explicit Sheet(LatticeKind kind = LatticeKind::Hexagonal) {
        const bool square = kind == LatticeKind::Square;
        params.sheet.size = {square ? 0.30 : 0.31, 0.17};
        params.sheet.dx = 0.01;
        params.sheet.lattice = kind;
        params.sheet.horizonFactor = square ? 1.5 : 2.5;
        params.material.density = 5000.0, params.material.capacity = 1.0;
        params.material.conductivity = 50.0;
        lattice = generateLattice(params.sheet);
        bonds = buildBondFamilies(lattice.positions, params.sheet.horizonFactor * params.sheet.dx);
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

/// Per directed bond: a rate of its own (no row has a class), a lattice's (proportional to
/// 1 / xi^2: a row of one direction is one value, or one plus whole steps of its last bit where
/// the coordinates' rounding moves xi), or each a few such steps apart on purpose.
enum class Rates { Random, Lattice, Stepped };

std::vector<double> ratesOf(const Sheet& sheet, Rates kind) {
    const BondFamilies& bonds = sheet.bonds;
    std::vector<double> rate(bonds.directedCount());
    for (std::size_t b = 0; b < rate.size(); ++b) {
        const double xi = bonds.restLength[b];
        rate[b] = kind == Rates::Random ? 10.0 * uniformFromHash(1, b) : 1e-3 / (xi * xi);
        if (kind == Rates::Stepped)
            rate[b] += double(b % 5) * std::ldexp(1.0, std::ilogb(rate[b]) - 52);
    }
    return rate;
}

class DiffusionTileSums : public ::testing::TestWithParam<std::tuple<LatticeKind, Rates>> {};

TEST_P(DiffusionTileSums, SumEachParticlesLivingBondsInOrder) {
    const auto [lattice, rates] = GetParam();
    const Sheet sheet(lattice);
    const BondFamilies& bonds = sheet.bonds;
    const int n = bonds.particleCount();
    ASSERT_NE(n % DiffusionTiles::kTile, 0);
    const std::vector<double> rate = ratesOf(sheet, rates);
    std::vector<double> theta(n);
    std::vector<std::uint8_t> alive(bonds.directedCount(), 1);
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
    // Random rates leave every row its own; a lattice's give most rows a class, and the
    // stepped ones most rows a stepped class (the sums above took those paths).
    constexpr int kTile = DiffusionTiles::kTile;
    const int allRows = tiles.tileBegin.back() / kTile;
    int stepped = 0;
    for (const int c : tiles.rowClass) stepped += c <= DiffusionTiles::kSteppedRate;
    if (rates == Rates::Random) EXPECT_EQ(tiles.classedRows(), 0);
    if (rates != Rates::Random) EXPECT_GT(tiles.classedRows(), allRows * 3 / 4);
    if (rates == Rates::Stepped) EXPECT_GT(stepped, allRows / 2);
    // On the square sheet, away from its first and last two rows, every row of a tile is a run
    // of consecutive partners, the tiles across a lattice row's end too (a row per offset): no
    // row gathers its theta.
    if (lattice != LatticeKind::Square) return;
    constexpr int kRow = 31;
    int rows = 0, runs = 0;
    for (int t = 2 * kRow / kTile + 1; kTile * (t + 1) + 2 * kRow < n; ++t)
        for (int u = tiles.tileBegin[t]; u < tiles.tileBegin[t + 1]; u += kTile) {
            bool run = true;
            for (int l = 0; l < kTile; ++l)
                run = run && tiles.partner[u + l] == tiles.partner[u] + l;
            EXPECT_EQ(tiles.rowRun[u / kTile], run ? tiles.partner[u] : -1);
            ++rows, runs += run;
        }
    EXPECT_GT(rows, 300);
    EXPECT_EQ(runs, rows);
}

INSTANTIATE_TEST_SUITE_P(
    Lattices, DiffusionTileSums,
    ::testing::Combine(::testing::Values(LatticeKind::Hexagonal, LatticeKind::Square),
                       ::testing::Values(Rates::Random, Rates::Lattice, Rates::Stepped)));

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
