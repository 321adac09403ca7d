// Eq. 25's sum in tiles of eight particles (sim/DiffusionKernels.h) has the bits of the loop over
// each particle's living bonds in order, at every vector width (ctest's kernels.* run this at
// each), and follows the bonds as they break.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <tuple>
#include <vector>

#include "sim/DamageState.h"
#include "sim/Diffusion.h"
#include "sim/PairKernels.h"
#include "sim/Random.h"
#include "sim/StepKernels.h"

using namespace rend::sim;

namespace {

/// A sheet whose particle count is not a multiple of 8, hexagonal with bonds within 2.5 dx, or
/// square within 1.5 dx (31 particles a row: a tile in four holds a row's end, as rows of one
/// offset): the edges' particles have fewer bonds than the interior's, so tiles there carry pads.
struct Sheet {
    /// horizon 0: the kind's above.
    explicit Sheet(LatticeKind kind = LatticeKind::Hexagonal, double horizon = 0.0) {
        const bool square = kind == LatticeKind::Square;
        params.sheet.size = {square ? 0.30 : 0.31, 0.17};
        params.sheet.dx = 0.01;
        params.sheet.lattice = kind;
        params.sheet.horizonFactor = horizon > 0.0 ? horizon : square ? 1.5 : 2.5;
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
    // Tiles of runs with one rate each sum as plain code (plainTile): never where
    // each rate is its own (DiffusionTilesPlain.SumAsTheLoopDoes below takes that path).
    const int tileCount = int(tiles.tileBegin.size()) - 1;
    ASSERT_EQ(int(tiles.plainTile.size()), tileCount);
    if (rates == Rates::Random)
        EXPECT_EQ(std::count(tiles.plainTile.begin(), tiles.plainTile.end(), 0), tileCount);
    for (int t = 0; t < tileCount; ++t)
        if (tiles.plainTile[t]) {
            EXPECT_EQ(tiles.tileBegin[t + 1] - tiles.tileBegin[t], kTile * tiles.plainTile[t]);
            for (int row = tiles.tileBegin[t] / kTile; row < tiles.tileBegin[t + 1] / kTile; ++row)
                EXPECT_TRUE(tiles.rowRun[row] >= 0 && tiles.rowClass[row] >= 0) << row;
        }
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

// A regular sheet's own rates (one exact value per direction) make most tiles plain: a run with
// one rate per row, summed as straight code with the rows' living bytes read as words; six rows
// on a hexagonal sheet, eight on a square one, twelve on a square one of horizon 2.2 (and 28 and
// 36 at horizon 3, by a loop), at every width (the AVX-512 sums took only the eight rows' as
// plain code before 2026-11-30). With some bonds dead, and tiles with all of them living, the
// sums keep the loop's bits, stored through the caches or around them.
struct PlainCase {
    LatticeKind lattice;
    double horizon;
    int rows;  ///< of its plain tiles
};

class DiffusionTilesPlain : public ::testing::TestWithParam<PlainCase> {};

TEST_P(DiffusionTilesPlain, SumAsTheLoopDoes) {
    const PlainCase c = GetParam();
    const Sheet sheet(c.lattice, c.horizon);
    const BondFamilies& bonds = sheet.bonds;
    const int n = bonds.particleCount();
    const Diffusion diffusion(sheet.params, sheet.lattice.positions, bonds, sheet.volumes);
    DiffusionTiles tiles = diffusion.tiles();
    std::vector<double> rate(bonds.directedCount(), 0.0);
    for (std::size_t u = 0; u < tiles.bond.size(); ++u)
        if (tiles.bond[u] >= 0) rate[tiles.bond[u]] = tiles.rate[u];
    std::vector<std::uint8_t> alive(bonds.directedCount(), 1);
    for (int b = 0; b < bonds.offsets[n / 2]; b += 11) alive[b] = 0;  // the first half's
    // In the second half every fifth tile's first particle loses its last bond only: a dead
    // bond in a tile's last row (past the first eight of twelve).
    constexpr int kTile = DiffusionTiles::kTile;
    for (int i = n / 2 + kTile; i < n; i += 5 * kTile) alive[bonds.offsets[i + 1] - 1] = 0;
    tiles.refresh(alive.data(), 1);
    std::vector<double> theta(n);
    for (int i = 0; i < n; ++i) theta[i] = 40.0 * (uniformFromHash(5, i) - 0.5);
    const double dt = 1e-3;
    const int whole = n / kTile;
    const std::vector<double> expected = naiveStep(bonds, rate, alive, theta, dt);
    // Stored through the caches and around them (as past the caches: the same values), into
    // 64-byte lines (a vector's heap block need not start on one).
    // Their measures (the largest change, the guard's theta sums) are those of the values left.
    for (const bool around : {false, true}) {
        std::vector<double> buffer(n + 8, -1.0);
        double* next = buffer.data() + (8 - (std::uintptr_t(buffer.data()) / 8) % 8) % 8;
        DiffusionMeasures measures;
        measures.largestChange = -1.0, measures.theta.firstBad = 7;
        diffuseTiles(tiles, theta.data(), next, dt, 0, whole, around, &measures);
        for (int i = kTile * whole; i < n; ++i) diffuseParticle(tiles, theta.data(), next, dt, i);
        EXPECT_EQ(std::memcmp(next, expected.data(), n * sizeof(double)), 0) << around;
        const std::size_t tiled = std::size_t(kTile) * whole;
        EXPECT_EQ(measures.largestChange, largestChange(theta.data(), expected.data(), tiled));
        const GuardSums sums = guardThetaSums(expected.data(), 0, int(tiled));
        EXPECT_EQ(measures.theta.maxAbsTheta, sums.maxAbsTheta);
        EXPECT_GT(sums.maxAbsTheta, 0.0);
        EXPECT_EQ(measures.theta.firstBad, -1);
    }
    int plain = 0, plainWithDead = 0;
    for (int t = 0; t < whole; ++t) {
        if (tiles.plainTile[t] != c.rows) continue;  // a square sheet's edges: 8 of 12 too
        ++plain;
        for (int row = tiles.tileBegin[t] / kTile; row < tiles.tileBegin[t + 1] / kTile; ++row)
            if (tiles.livingRows[row] != 0xff) {
                ++plainWithDead;
                break;
            }
    }
    EXPECT_GT(plain, whole / 2) << "of " << whole;
    EXPECT_GT(plainWithDead, 0);
    EXPECT_LT(plainWithDead, plain);
}

INSTANTIATE_TEST_SUITE_P(Lattices, DiffusionTilesPlain,
                         ::testing::Values(PlainCase{LatticeKind::Hexagonal, 1.5, 6},
                                           PlainCase{LatticeKind::Square, 1.5, 8},
                                           PlainCase{LatticeKind::Square, 2.2, 12},
                                           PlainCase{LatticeKind::Square, 3.0, 28},
                                           PlainCase{LatticeKind::Hexagonal, 3.0, 36}));

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
    early.advance(a, damage, 0.0, dt);
    EXPECT_NE(a, theta);
    for (const double value : a) ASSERT_TRUE(std::isfinite(value));
    for (int b = 0; b < int(sheet.bonds.directedCount()); b += 7) damage.breakBond(b);
    Diffusion late(sheet.params, sheet.lattice.positions, sheet.bonds, sheet.volumes);
    std::vector<double> b = a;
    early.advance(a, damage, dt, dt);
    late.advance(b, damage, dt, dt);
    EXPECT_EQ(a, b);
}

// Diffusion::lastChange() bounds every |theta change| of the last advance(), sub-steps, spots
// (two overlapping, one a sink) and held edges included, and is no more than the sum of each
// sub-step's largest diffusion and the spots' dt |rate| (the held edge's jump is larger).
TEST(DiffusionTiles, TheLastChangeBoundsEveryParticlesChange) {
    Sheet sheet;
    sheet.params.diffusion.spots.push_back({{0.0, 0.0}, 0.05, 30.0});
    sheet.params.diffusion.spots.push_back({{0.02, 0.0}, 0.05, -10.0});
    const int n = sheet.bonds.particleCount();
    Diffusion diffusion(sheet.params, sheet.lattice.positions, sheet.bonds, sheet.volumes);
    DamageState damage(sheet.bonds, sheet.lattice.triangles);
    std::vector<double> theta(n);
    for (int i = 0; i < n; ++i) theta[i] = uniformFromHash(9, i);
    EXPECT_EQ(diffusion.lastChange(), -1.0) << "not asked for";
    diffusion.measureChanges();
    EXPECT_EQ(diffusion.lastChange(), 0.0);
    for (const double steps : {0.5, 2.5}) {  // one sub-step, then three
        const double dt = steps * diffusion.stableTimeStep();
        const std::vector<double> before = theta;
        diffusion.advance(theta, damage, 0.0, dt);
        double largest = 0.0;
        for (int i = 0; i < n; ++i) largest = std::max(largest, std::fabs(theta[i] - before[i]));
        EXPECT_GE(diffusion.lastChange(), largest) << steps;
        EXPECT_LE(diffusion.lastChange(), 3.0 * largest + 40.0 * dt) << steps;
    }
    sheet.params.diffusion.edges.push_back({});
    sheet.params.diffusion.edges.back().value = 50.0;
    Diffusion held(sheet.params, sheet.lattice.positions, sheet.bonds, sheet.volumes);
    held.measureChanges();
    const std::vector<double> before = theta;
    held.advance(theta, damage, 0.0, 0.5 * held.stableTimeStep());
    double largest = 0.0;
    for (int i = 0; i < n; ++i) largest = std::max(largest, std::fabs(theta[i] - before[i]));
    EXPECT_GT(largest, 40.0);
    EXPECT_GE(held.lastChange(), largest);
}

// The guard's half of its sums that reads theta (sim/StepKernels.h's guardThetaSums: the largest
// |theta|, the lowest index not finite), taken by the diffusion as it writes each chunk of 64
// tiles, are those of the theta it leaves: with spots burning on particles of chunks summed
// before (the largest |theta| theirs), an edge held (at one sub-step and at three), the few
// particles past the whole tiles, and a NaN spreading from one particle.
TEST(DiffusionTiles, TheGuardsSumsAreThoseOfTheThetaLeft) {
    Sheet sheet;
    sheet.params.sheet.size = {1.01, 0.4};  // 4,141 hexagonal particles: eight chunks and a tail
    sheet.lattice = generateLattice(sheet.params.sheet);
    sheet.bonds = buildBondFamilies(sheet.lattice.positions, 2.5 * sheet.params.sheet.dx);
    sheet.volumes.assign(sheet.lattice.positions.size(),
                         sheet.lattice.particleArea * sheet.params.sheet.thickness);
    const int n = sheet.bonds.particleCount();
    ASSERT_GT(n, 8 * 512 + 8);
    ASSERT_NE(n % 8, 0);
    sheet.params.diffusion.spots.push_back({{0.3, 0.1}, 0.03, 4e4});
    sheet.params.diffusion.spots.push_back({{-0.2, 0.0}, 0.03, -3e4});
    DamageState damage(sheet.bonds, sheet.lattice.triangles);
    const auto expectSums = [&](const Diffusion& d, const std::vector<double>& theta,
                                const char* what) {
        const GuardSums expected = guardThetaSums(theta.data(), 0, n);
        ASSERT_NE(d.thetaSums(), nullptr) << what;
        EXPECT_EQ(d.thetaSums()->maxAbsTheta, expected.maxAbsTheta) << what;
        EXPECT_EQ(d.thetaSums()->firstBad, expected.firstBad) << what;
    };
    Diffusion spots(sheet.params, sheet.lattice.positions, sheet.bonds, sheet.volumes);
    EXPECT_EQ(spots.thetaSums(), nullptr) << "before the first advance";
    std::vector<double> theta(n);
    for (int i = 0; i < n; ++i) theta[i] = uniformFromHash(4, i) - 0.5;
    for (const double steps : {0.5, 2.5}) {
        spots.advance(theta, damage, 0.0, steps * spots.stableTimeStep());
        expectSums(spots, theta, "spots");
        const double largest = *std::max_element(theta.begin(), theta.end());
        EXPECT_EQ(spots.thetaSums()->maxAbsTheta, largest) << "a spot's particle";
    }
    theta[n - 1] = -1e6;  // past the whole tiles
    spots.advance(theta, damage, 0.0, 0.5 * spots.stableTimeStep());
    expectSums(spots, theta, "the last particle");
    EXPECT_GT(spots.thetaSums()->maxAbsTheta, 5e5);
    sheet.params.diffusion.edges.push_back({});  // the left edge's strip
    sheet.params.diffusion.edges.back().region.max.x() = -0.45;
    sheet.params.diffusion.edges.back().value = -5000.0;
    Diffusion held(sheet.params, sheet.lattice.positions, sheet.bonds, sheet.volumes);
    for (int i = 0; i < n; ++i) theta[i] = uniformFromHash(4, i) - 0.5;
    for (const double steps : {0.5, 2.5}) {
        held.advance(theta, damage, 0.0, steps * held.stableTimeStep());
        expectSums(held, theta, "held");
        EXPECT_EQ(held.thetaSums()->maxAbsTheta, 5000.0) << "the held particles'";
    }
    // A NaN in the third chunk, which no spot touches: it spreads to its partners, the lowest
    // of them inside a tile (not its first lane).
    for (int i = 0; i < n; ++i) theta[i] = uniformFromHash(4, i) - 0.5;
    const int bad = 2 * 512 + 77;
    theta[bad] = std::numeric_limits<double>::quiet_NaN();
    spots.advance(theta, damage, 0.0, 0.5 * spots.stableTimeStep());
    expectSums(spots, theta, "a NaN");
    const int firstBad = spots.thetaSums()->firstBad;
    EXPECT_GE(firstBad, 512);
    EXPECT_LT(firstBad, bad);
    EXPECT_NE(firstBad % 8, 0);
}

}  // namespace

namespace {

/// Sheet's bonds rebuilt with its particles moved: far from the origin (their coordinates'
/// rounding spreads a direction's rest lengths over many last bits), or off the lattice.
void moveParticles(Sheet& sheet, bool far, bool jitter) {
    for (std::size_t i = 0; i < sheet.lattice.positions.size(); ++i) {
        Eigen::Vector3d& x = sheet.lattice.positions[i];
        if (far) x += Eigen::Vector3d(40.3, -23.7, 0.0);
        if (jitter)
            x += 1e-3 * sheet.params.sheet.dx *
                 Eigen::Vector3d(uniformFromHash(3, 2 * i), uniformFromHash(3, 2 * i + 1), 0.0);
    }
    sheet.bonds = buildBondFamilies(sheet.lattice.positions,
                                    sheet.params.sheet.horizonFactor * sheet.params.sheet.dx);
}

/// Eq. 25's rate of directed bond b at length xi (sim/Diffusion.h).
double rateAt(const Diffusion& d, const Sheet& sheet, int b, double xi, double weight) {
    const MaterialParams& m = sheet.params.material;
    return d.coefficient() * weight * sheet.volumes[sheet.bonds.partners[b]] /
           (m.density * m.capacity * xi * xi);
}

}  // namespace

// A lattice's bonds take eq. 25's rate at their exact length dx sqrt(k): far from the origin,
// where the rest lengths of one direction differ in their last bits, every row of rates is still
// one value (no steps to stream), and the rates are the lattice's to the bit.
TEST(DiffusionRates, ALatticeTakesItsExactLengths) {
    for (const LatticeKind kind : {LatticeKind::Square, LatticeKind::Hexagonal}) {
        Sheet sheet(kind);
        moveParticles(sheet, true, false);
        const Diffusion diffusion(sheet.params, sheet.lattice.positions, sheet.bonds,
                                  sheet.volumes);
        const DiffusionTiles& tiles = diffusion.tiles();
        const int rows = int(tiles.rowClass.size());
        const auto stepped = std::count_if(tiles.rowClass.begin(), tiles.rowClass.end(),
                                           [](int c) { return c <= DiffusionTiles::kSteppedRate; });
        EXPECT_EQ(stepped, 0) << "of " << rows << " rows";
        const Sheet home(kind);  // at the origin: the rows that mix directions are per bond
        const Diffusion atHome(home.params, home.lattice.positions, home.bonds, home.volumes);
        EXPECT_EQ(tiles.classedRows(), atHome.tiles().classedRows());
        EXPECT_GT(tiles.classedRows(), rows * 9 / 10);
        const double dx = sheet.params.sheet.dx;
        const double horizon = sheet.params.sheet.horizonFactor * dx;
        int checked = 0;
        for (std::size_t u = 0; u < tiles.bond.size(); ++u) {
            const int b = tiles.bond[u];
            if (b < 0) continue;
            const double k = std::round(std::pow(sheet.bonds.restLength[b] / dx, 2));
            const double xi = dx * std::sqrt(k);
            ASSERT_EQ(tiles.rate[u], rateAt(diffusion, sheet, b, xi, 1.0 - xi / horizon)) << u;
            checked += sheet.bonds.restLength[b] != xi;
        }
        EXPECT_GT(checked, 100) << "rest lengths off their lattice's by rounding";
    }
}

// Off a lattice, each bond keeps the rate of its own rest length and W0.
TEST(DiffusionRates, OffALatticeEachBondKeepsItsOwnLength) {
    Sheet sheet(LatticeKind::Square);
    moveParticles(sheet, false, true);
    const Diffusion diffusion(sheet.params, sheet.lattice.positions, sheet.bonds, sheet.volumes);
    const DiffusionTiles& tiles = diffusion.tiles();
    for (std::size_t u = 0; u < tiles.bond.size(); ++u)
        if (const int b = tiles.bond[u]; b >= 0)
            ASSERT_EQ(tiles.rate[u],
                      rateAt(diffusion, sheet, b, sheet.bonds.restLength[b], sheet.bonds.weight[b]))
                << u;
}
