#pragma once
// The second pass of the vectorised force loop (sim/PairKernels.h computes each pair's force
// into a slot): each particle's sum of its living bonds' pair forces in CSR order, minus where it
// is the pair's larger index (sim/Bonds.h's BondPairs). One particle at a time, or, with
// AVX-512, eight at once (with AVX2 and BMI2, as two halves of four; a tile of several groups
// one particle at a time): a tile (sim/PeridynamicBonds.h's order) whose particles have the same
// number of bonds, the same number of lower copies and, bond by bond, their pairs in at most two
// runs of consecutive slots, as almost every tile of a regular lattice has; or a tile whose
// particles' bonds differ (where a lattice's row ends) as one group over their partner offsets,
// in at most three runs. Each lane adds the same terms in the same order as one particle's
// loop, skipping the dead bonds (and the bonds it does not have) by a mask: the same bits.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace rend::sim {

/// The tiles of kTile particles whose sums run eight lanes wide, each in groups of
/// consecutive lanes with the same number of bonds and of lower copies among them, whose k-th
/// bonds' pairs lie in at most two runs of consecutive slots (a tile inside a regular lattice's
/// row is one group), or one union group (below) where a lattice's row ends.
struct PairSumTiles {
    static constexpr int kTile = 8;
    static constexpr int kMostBonds = 64;  ///< a lane's life flags in one 64-bit word
    std::vector<int> groupFirst;           ///< per whole tile, and one past the last
    struct Group {
        std::uint8_t firstLane, endLane, bonds, lower;  ///< bonds 0: one particle at a time
        int rowFirst;
        /// Every row's lanes lie in one run (fromA all lanes), and half the bonds are lower
        /// copies: a tile inside a regular lattice.
        bool regular = false;
    };
    std::vector<Group> groups;
    /// A row (the k-th bonds of a group's lanes side by side): where lane 0's x would lie in
    /// each run's slots (lane l's is l after), and the lanes whose pairs lie in run A (the rest
    /// in run B).
    struct Row {
        int atA, atB;
        std::uint8_t fromA;
    };
    std::vector<Row> rows;
    /// A tile whose lanes differ in their bonds (where a lattice's row ends: its last particle
    /// and the next row's first have fewer), summed as one group: a row per partner offset j - i
    /// of any lane, in increasing order (each lane's bond order), the lanes without a bond of
    /// that offset masked off. Its group has lower == kUnion and rowFirst into unionRows.
    static constexpr std::uint8_t kUnion = 255;
    struct UnionRow {
        int at[3];             ///< where lane 0's x would lie in each run's slots
        std::uint8_t from[3];  ///< the lanes of each run (from[1], from[2] may be 0)
        std::uint8_t having;   ///< the lanes with a bond of this offset
        bool minus;            ///< a lower copy's offset: taken away
        std::uint64_t select;  ///< those bonds' life flags among the tile's (one bit per lane)
    };
    std::vector<UnionRow> unionRows;
    int directedBonds = 0;  ///< offsets[n]

    /// The tiles of particles [0, n) from the CSR offsets, upper copies' starts, where each
    /// directed bond's pair's x lies in the slots (PairGather::pairOf in rows; -1: none) and
    /// each one's partner. A run is any eight consecutive slots.
    static PairSumTiles build(const int* offsets, const int* upperBegin, const int* slotOf,
                              const int* partners, int n);
};

struct PairGather {
    const int* offsets = nullptr;
    const int* upperBegin = nullptr;
    /// Per directed bond: its pair u, or in rows where its pair's x lies in pairForce.
    const int* pairOf = nullptr;
    const std::uint8_t* alive = nullptr;
    /// LinearPairOutput::force: pair u at slotAt(u & slotMask, false) (sim/PairKernels.h); in
    /// rows, x at pairOf, y and z `stride` and twice that after, with kPairTile readable
    /// doubles before each and after (read, never summed).
    const double* pairForce = nullptr;
    /// x y z per particle from particle forceFirst (a fused block's own), or from 0 (the whole
    /// force array).
    double* force = nullptr;
    unsigned slotMask = ~0u;              ///< a ring of 2^k slots, or all bits: slot u is pair u
    const PairSumTiles* tiles = nullptr;  ///< null: one particle at a time
    bool rows = false;                    ///< the slots are in rows (slotRows())
    /// The tile sums' stores bypass the caches (streamsForces()), where force lies on 64-byte
    /// lines (writesAround()).
    bool stream = false;
    int stride = 8;  ///< in rows: from a slot's x to its y
    int forceFirst = 0;
    /// Per tile of kTile particles: nonzero where all its bonds live (as of the life flags'
    /// version: PeridynamicBonds::livingTiles()); null: the sums read the tile's flags.
    const std::uint8_t* tileLiving = nullptr;
    /// Particle i's x y z.
    double* forceOf(int i) const { return force + 3 * (std::ptrdiff_t(i) - forceFirst); }
};

/// Particles [begin, end).
void gatherPairForces(const PairGather& g, int begin, int end);

/// Whether a step over `particles` streams more than the last-level cache holds (about 250
/// bytes per particle: positions, velocities, forces, the sums' rows and life flags). Then the
/// force array is gone from the caches before the kick reads it, and a store that first reads
/// its line (24 of those bytes) is wasted: the tile sums write around the caches instead
/// (10^6 particles, interleaved: 12.1 -> 11.8 ns on one thread, 6.7 -> 6.7 on two; at 10^5,
/// which fits, it cost 8.3 -> 9.2, so not there).
bool streamsForces(long long particles);

/// Whether gatherPairForces() writes g's tiles around the caches.
bool writesAround(const PairGather& g);

/// The last-level cache's size in bytes, as the system lists it for CPU 0.
long long lastLevelCacheBytes();

}  // namespace rend::sim
