// Each particle's sum of its pair forces (sim/PairSums.h): eight particles at once, in groups of
// lanes, has the bits of one particle at a time, for any range, any ring of slots, dead bonds and
// any lattice (ctest's kernels.* run this at each vector width).

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <vector>

#include "sim/Bonds.h"
#include "sim/Lattice.h"
#include "sim/PairKernels.h"
#include "sim/PairSums.h"
#include "sim/Random.h"
#include "sim/StepKernels.h"

using namespace rend::sim;

namespace {

constexpr int kTile = PairSumTiles::kTile;

BondFamilies sheetBonds(double width, double height, LatticeKind kind, double horizon) {
    SheetParams sheet;
    sheet.size = {width, height};
    sheet.dx = 0.01;
    sheet.lattice = kind;
    return buildBondFamilies(generateLattice(sheet).positions, horizon * sheet.dx);
}

/// Each directed bond's pair as PeridynamicBonds numbers them: the k-th upper copy of tile t's
/// lane l is pair first(t) + kTile k + l; a lower copy has its upper copy's pair.
std::vector<int> tilePairs(const BondFamilies& bonds, const BondPairs& pairs) {
    const int n = bonds.particleCount();
    std::vector<int> pairOf(bonds.directedCount(), -1);
    int first = 0;
    for (int t = 0; t * kTile < n; ++t) {
        int most = 0;
        for (int i = kTile * t; i < std::min(n, kTile * (t + 1)); ++i)
            most = std::max(most, bonds.offsets[i + 1] - pairs.upperBegin[i]);
        for (int i = kTile * t; i < std::min(n, kTile * (t + 1)); ++i)
            for (int b = pairs.upperBegin[i]; b < bonds.offsets[i + 1]; ++b) {
                const int u = first + kTile * (b - pairs.upperBegin[i]) + i % kTile;
                pairOf[b] = pairOf[pairs.twin[pairs.pairOf[b]]] = u;
            }
        first += kTile * most;
    }
    return pairOf;
}

/// Where each directed bond's pair's x lies, and how far its y lies after, for slots in rows.
struct Layout {
    std::vector<int> slot;
    int stride = kPairTile;
};

/// A ring of slotMask + 1 pairs in rows of eight (slotAt()).
Layout ringOfPairs(const std::vector<int>& pairOf, unsigned slotMask) {
    Layout l;
    for (const int u : pairOf)
        l.slot.push_back(u < 0 ? -1 : int(slotAt(unsigned(u) & slotMask, true)));
    return l;
}

/// PeridynamicBonds' layout: the k-th rows of a ring of `ringTiles` consecutive tiles side by
/// side, k by k, each k's ring a line longer than its tiles (pairs numbered as tilePairs()).
Layout ringOfRows(const BondFamilies& bonds, const BondPairs& pairs, int ringTiles) {
    const int n = bonds.particleCount(), ringOfK = kTile * (ringTiles + 1);
    std::vector<int> rowSlot;
    int most = 1;
    for (int t = 0; t * kTile < n; ++t) {
        int rows = 0;
        for (int i = kTile * t; i < std::min(n, kTile * (t + 1)); ++i)
            rows = std::max(rows, bonds.offsets[i + 1] - pairs.upperBegin[i]);
        for (int k = 0; k < rows; ++k) rowSlot.push_back(k * ringOfK + kTile * (t % ringTiles));
        most = std::max(most, rows);
    }
    Layout l;
    for (const int u : tilePairs(bonds, pairs))
        l.slot.push_back(u < 0 ? -1 : rowSlot[u / kTile] + u % kTile);
    l.stride = most * ringOfK + kPairTile;
    return l;
}

struct Sums {
    explicit Sums(const BondFamilies& bonds, Layout layout)
        : bonds(bonds),
          pairs(buildBondPairs(bonds)),
          layout(std::move(layout)),
          alive(bonds.directedCount(), 1),
          tiles(PairSumTiles::build(bonds.offsets.data(), this->pairs.upperBegin.data(),
                                    this->layout.slot.data(), bonds.partners.data(),
                                    bonds.particleCount())) {
        const int last = *std::max_element(this->layout.slot.begin(), this->layout.slot.end());
        slots.assign(kTile + 2 * std::size_t(this->layout.stride) + last + 2 * kTile, 0.0);
        for (std::size_t k = kTile; k < slots.size(); ++k)
            slots[k] = 2.0 * uniformFromHash(11, int(k)) - 1.0;
        // Some dead in the first half of the bonds, where most tiles have one; some "alive"
        // as 2; every bond of the second half's tiles alive.
        const int half = int(alive.size()) / 2;
        for (int b = 0; b < int(alive.size()); ++b) {
            const double draw = uniformFromHash(12, b);
            alive[b] = draw < 0.1 && b < half ? 0 : draw < 0.2 ? 2 : 1;
        }
    }
    /// The sums of particles [begin, end), with or without the tiles, with their stores
    /// around the caches or not, with each tile's life in a byte (PairGather::tileLiving) or not.
    std::vector<double> of(int begin, int end, bool withTiles, bool stream = false,
                           bool tileBytes = false) const {
        const std::size_t size = 3 * std::size_t(bonds.particleCount());
        std::vector<double> buffer(size + 8, -7.0);
        double* force = buffer.data();  // on a 64-byte line, as streamed stores need
        while (reinterpret_cast<std::uintptr_t>(force) % 64 != 0) ++force;
        PairGather g{bonds.offsets.data(),
                     pairs.upperBegin.data(),
                     layout.slot.data(),
                     alive.data(),
                     slots.data() + kTile,
                     force,
                     ~0u,
                     withTiles ? &tiles : nullptr,
                     true,
                     stream,
                     layout.stride};
        // Whether each tile's bonds all live, read from the flags as PeridynamicBonds does.
        const int n = bonds.particleCount();
        std::vector<std::uint8_t> living;
        for (int t = 0; kTile * t < n; ++t) {
            const int first = bonds.offsets[kTile * t],
                      last = bonds.offsets[std::min(n, kTile * (t + 1))];
            living.push_back(std::count(alive.begin() + first, alive.begin() + last, 0) == 0);
        }
        if (tileBytes) g.tileLiving = living.data();
        if (stream && withTiles && simdWidth() == 8) {
            EXPECT_TRUE(writesAround(g));
        }
        gatherPairForces(g, begin, end);
        return std::vector<double>(force, force + size);
    }
    const BondFamilies& bonds;
    BondPairs pairs;
    Layout layout;
    std::vector<std::uint8_t> alive;
    PairSumTiles tiles;
    std::vector<double> slots;
};

void expectSameBits(const Sums& sums, int begin, int end) {
    const std::vector<double> alone = sums.of(begin, end, false), tiled = sums.of(begin, end, true);
    EXPECT_EQ(std::memcmp(alone.data(), tiled.data(), alone.size() * sizeof(double)), 0)
        << "particles " << begin << " to " << end;
    const std::vector<double> streamed = sums.of(begin, end, true, true);
    EXPECT_EQ(std::memcmp(alone.data(), streamed.data(), alone.size() * sizeof(double)), 0)
        << "particles " << begin << " to " << end << ", stored around the caches";
    const std::vector<double> bytes = sums.of(begin, end, true, false, true);
    EXPECT_EQ(std::memcmp(alone.data(), bytes.data(), alone.size() * sizeof(double)), 0)
        << "particles " << begin << " to " << end << ", each tile's life in a byte";
}

struct Case {
    LatticeKind lattice;
    /// In dx: 1.5 gives 8 bonds (square) or 6 (hexagonal); 2.2 gives 12; 3 gives 28 (square;
    /// a lane's flags in a word of two lanes) or 36 (hexagonal: a word a lane).
    double horizon;
};

class PairSums : public ::testing::TestWithParam<Case> {};

TEST_P(PairSums, HaveTheBitsOfOneParticleAtATime) {
    const Case c = GetParam();
    const BondFamilies bonds = sheetBonds(0.23, 0.11, c.lattice, c.horizon);
    const int n = bonds.particleCount();
    const BondPairs pairs = buildBondPairs(bonds);
    for (const unsigned slotMask : {~0u, 63u}) {  // every pair its slot, or a ring of 64
        const Sums tiled(bonds, ringOfPairs(tilePairs(bonds, pairs), slotMask));
        expectSameBits(tiled, 0, n);
        expectSameBits(tiled, 3, n - 5);  // ranges that start and end inside a tile
        const Sums csr(bonds, ringOfPairs(pairs.pairOf, slotMask));  // CSR pairs: few runs
        expectSameBits(csr, 0, n);
    }
    for (const int ringTiles : {4, 1 << 20}) {  // rows by k, wrapping often or never
        const Sums byRow(bonds, ringOfRows(bonds, pairs, ringTiles));
        expectSameBits(byRow, 0, n);
        expectSameBits(byRow, 3, n - 5);
    }
}

INSTANTIATE_TEST_SUITE_P(
    Lattices, PairSums,
    ::testing::Values(Case{LatticeKind::Square, 1.5}, Case{LatticeKind::Hexagonal, 1.5},
                      Case{LatticeKind::Square, 2.2}, Case{LatticeKind::Hexagonal, 2.5},
                      Case{LatticeKind::Square, 3.0}, Case{LatticeKind::Hexagonal, 3.0}));

// Wide horizons: a tile inside a lattice's row is one group of eight lanes however many bonds
// its particles have, up to PairSumTiles::kMostBonds (their sums by rows, checked bit for bit
// above); past it, one particle at a time.
TEST(PairSumTiles, TilesOfUpToSixtyFourBondsAreGroupsOfEightLanes) {
    for (const auto& [kind, horizon, bonds] :
         {std::tuple{LatticeKind::Square, 3.0, 28}, std::tuple{LatticeKind::Hexagonal, 3.0, 36},
          std::tuple{LatticeKind::Square, 4.0, 48}, std::tuple{LatticeKind::Square, 4.5, 68}}) {
        const BondFamilies family = sheetBonds(0.6, 0.3, kind, horizon);
        const BondPairs pairs = buildBondPairs(family);
        const Layout layout = ringOfRows(family, pairs, 1 << 20);
        const PairSumTiles tiles =
            PairSumTiles::build(family.offsets.data(), pairs.upperBegin.data(), layout.slot.data(),
                                family.partners.data(), family.particleCount());
        int whole = 0, interior = 0;
        for (int t = 0; t + 1 < int(tiles.groupFirst.size()); ++t) {
            bool inside = true;  // every lane with the interior's bonds
            for (int i = kTile * t; i < kTile * (t + 1); ++i)
                inside = inside && family.offsets[i + 1] - family.offsets[i] == bonds;
            if (!inside) continue;
            ++interior;
            const PairSumTiles::Group& g = tiles.groups[tiles.groupFirst[t]];
            whole += tiles.groupFirst[t + 1] - tiles.groupFirst[t] == 1 && g.endLane == kTile &&
                     g.bonds == bonds;
        }
        ASSERT_GT(interior, 20) << "horizon " << horizon;
        // A few tiles of full lanes hold rows in more than two runs of slots.
        if (bonds <= PairSumTiles::kMostBonds)
            EXPECT_GE(whole, interior * 9 / 10)
                << "horizon " << horizon << ", " << bonds << " bonds";
        else
            EXPECT_EQ(whole, 0) << "horizon " << horizon << ", " << bonds << " bonds";
    }
}

/// A square sheet of 24 + 1 particles per row and its sums' tiles: many tiles lie inside a
/// row, the others cross its end.
struct RowsOf25 {
    RowsOf25()
        : bonds(sheetBonds(0.24, 0.1, LatticeKind::Square, 1.5)),
          pairs(buildBondPairs(bonds)),
          slot(ringOfPairs(tilePairs(bonds, pairs), 63u).slot),
          tiles(PairSumTiles::build(bonds.offsets.data(), pairs.upperBegin.data(), slot.data(),
                                    bonds.partners.data(), bonds.particleCount())) {}
    static constexpr int rowLength = 25;
    BondFamilies bonds;
    BondPairs pairs;
    std::vector<int> slot;
    PairSumTiles tiles;
};

TEST(PairSumTiles, TileInsideALatticeRowIsOneGroupOfEightLanes) {
    const RowsOf25 sheet;
    const BondFamilies& bonds = sheet.bonds;
    const PairSumTiles& tiles = sheet.tiles;
    const int rowLength = RowsOf25::rowLength, tileCount = bonds.particleCount() / kTile;
    int whole = 0, inside = 0;
    for (int t = 0; t < tileCount; ++t) {
        const int first = kTile * t, last = first + kTile - 1;
        // Inside a row, and so are its lower copies' partners (one column further left).
        const bool interior = first / rowLength == last / rowLength && first % rowLength > 1 &&
                              last % rowLength < rowLength - 2 && first >= rowLength &&
                              last < bonds.particleCount() - rowLength;
        if (!interior) continue;
        ++inside;
        const int groups = tiles.groupFirst[t + 1] - tiles.groupFirst[t];
        const PairSumTiles::Group& g = tiles.groups[tiles.groupFirst[t]];
        whole += groups == 1 && g.endLane == kTile && g.bonds == 8 && g.lower == 4;
    }
    EXPECT_GT(inside, 10);
    EXPECT_EQ(whole, inside);
    // Every lane of every whole tile is in exactly one group, in order.
    for (int t = 0; t < tileCount; ++t) {
        int lane = 0;
        for (int q = tiles.groupFirst[t]; q < tiles.groupFirst[t + 1]; ++q) {
            EXPECT_EQ(tiles.groups[q].firstLane, lane);
            lane = tiles.groups[q].endLane;
        }
        EXPECT_EQ(lane, kTile);
    }
}

// A tile that holds a row's last particle and the next row's first (5 bonds each, against 8)
// is summed as one group: a row per partner offset, the lanes without it masked off (its
// bits are PairSums.HaveTheBitsOfOneParticleAtATime's).
TEST(PairSumTiles, TileAcrossARowsEndIsOneUnionGroup) {
    const RowsOf25 sheet;
    const BondFamilies& bonds = sheet.bonds;
    const PairSumTiles& tiles = sheet.tiles;
    const int rowLength = RowsOf25::rowLength, tileCount = bonds.particleCount() / kTile;
    int across = 0, unions = 0;
    for (int t = 0; t < tileCount; ++t) {
        const int first = kTile * t, last = first + kTile - 1;
        // Across a row's end, between the sheet's second and second-to-last rows.
        if (first / rowLength == last / rowLength || first < 2 * rowLength ||
            last >= bonds.particleCount() - 2 * rowLength)
            continue;
        ++across;
        const PairSumTiles::Group& g = tiles.groups[tiles.groupFirst[t]];
        if (tiles.groupFirst[t + 1] - tiles.groupFirst[t] != 1 || g.lower != PairSumTiles::kUnion)
            continue;
        ++unions;
        EXPECT_EQ(g.bonds, 8) << "tile " << t << ": the eight offsets of the square lattice";
        int having = 0;
        for (int q = g.rowFirst; q < g.rowFirst + g.bonds; ++q)
            having += std::popcount(unsigned(tiles.unionRows[q].having));
        EXPECT_EQ(having, bonds.offsets[last + 1] - bonds.offsets[first]) << "tile " << t;
    }
    EXPECT_GT(across, 3);
    EXPECT_EQ(unions, across);
}

}  // namespace
