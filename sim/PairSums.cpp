#include "sim/PairSums.h"

#include <immintrin.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <fstream>
#include <string>

#include "sim/PairKernels.h"
#include "sim/SimdRuns.h"
#include "sim/StepKernels.h"

namespace rend::sim {
namespace {

constexpr int kTile = PairSumTiles::kTile;
/// A group of one lane is summed as one particle: its rows would cost more than its own loop.
constexpr int kFewestLanes = 2;

/// The lanes of a group's life flags per 64-bit word (bit k of lane l at l * bonds + k): all of
/// them where they fit, else 4, 2 or 1 (the most that fit), so that a word's lanes are a power
/// of two and its last lanes' flags never spill into the next.
constexpr int lanesPerWordOf(int bonds, int lanes) {
    if (bonds * lanes <= 64) return lanes;
    int most = kTile / 2;
    while (most > 1 && most * bonds > 64) most /= 2;
    return most;
}

/// A particle's bonds and lower copies among them.
struct Shape {
    int bonds, lower;
    bool operator==(const Shape&) const = default;
};

/// The rows of a group of a tile's lanes [first, end) grown one lane at a time: per row (its
/// lanes' k-th bonds), where its slots lie as at most two runs of consecutive slots, run A (lane
/// l's x at a + l) up to lane `split` and run B (b + l) from it.
struct GroupRows {
    std::vector<int> a, b, split;  ///< split < 0: one run so far
    std::vector<int> slots;        ///< the next lane's slots, per row

    /// Lane `first` alone: whether each of its bonds has a slot.
    bool start(const int* offsets, const int* slotOf, int i, int lane, int bonds) {
        a.assign(bonds, 0), b.assign(bonds, 0), split.assign(bonds, -1);
        for (int k = 0; k < bonds; ++k) {
            const int slot = slotOf[offsets[i] + k];
            if (slot < 0) return false;
            a[k] = b[k] = slot - lane;
        }
        return true;
    }
    /// Lane `lane` (particle i) added where each row keeps at most two runs; else unchanged.
    bool extend(const int* offsets, const int* slotOf, int i, int lane) {
        const int bonds = int(a.size());
        slots.resize(bonds);
        for (int k = 0; k < bonds; ++k) {
            const int slot = slotOf[offsets[i] + k];
            slots[k] = slot - lane;
            const bool fits = split[k] < 0 ? true : slots[k] == b[k];
            if (slot < 0 || !fits) return false;
        }
        for (int k = 0; k < bonds; ++k)
            if (split[k] < 0 && slots[k] != a[k]) split[k] = lane, b[k] = slots[k];
        return true;
    }
};

/// Tile t as one union group (PairSumTiles::kUnion): its rows appended to `rows`, or false
/// where it cannot be (a lane's bonds not in increasing offset, more than 64 life flags, a row
/// in more than three runs).
bool unionOf(const int* offsets, const int* upperBegin, const int* slotOf, const int* partners,
             int t, std::vector<PairSumTiles::UnionRow>& rows) {
    const int base = offsets[kTile * t];
    if (offsets[kTile * (t + 1)] - base > 64) return false;
    std::vector<int> all;
    for (int l = 0; l < kTile; ++l) {
        const int i = kTile * t + l;
        for (int b = offsets[i]; b < offsets[i + 1]; ++b) {
            const int d = partners[b] - i;
            if ((b > offsets[i] && d <= partners[b - 1] - i) || (d < 0) != (b < upperBegin[i]))
                return false;
            all.push_back(d);
        }
    }
    std::sort(all.begin(), all.end());
    all.erase(std::unique(all.begin(), all.end()), all.end());
    if (all.size() > 254) return false;
    std::vector<PairSumTiles::UnionRow> made;
    for (const int d : all) {
        PairSumTiles::UnionRow r{{0, 0, 0}, {0, 0, 0}, 0, d < 0, 0};
        int runs = 0;
        for (int l = 0; l < kTile; ++l) {
            const int i = kTile * t + l;
            const int* end = partners + offsets[i + 1];
            const int* found = std::find(partners + offsets[i], end, i + d);
            if (found == end) continue;
            const int b = int(found - partners), slot = slotOf[b];
            if (slot < 0) return false;
            r.having |= std::uint8_t(1u << l), r.select |= std::uint64_t(1) << (b - base);
            // Lanes whose lane-0 positions agree are one run.
            const int where = slot - l;
            int k = 0;
            while (k < runs && r.at[k] != where) ++k;
            if (k == runs) {
                if (runs == 3) return false;
                r.at[runs++] = where;
            }
            r.from[k] |= std::uint8_t(1u << l);
        }
        made.push_back(r);
    }
    rows.insert(rows.end(), made.begin(), made.end());
    return true;
}

}  // namespace

PairSumTiles PairSumTiles::build(const int* offsets, const int* upperBegin, const int* slotOf,
                                 const int* partners, int n) {
    PairSumTiles s;
    s.directedBonds = offsets[n];
    const int tiles = n / kTile;
    s.groupFirst.assign(tiles + 1, 0);
    GroupRows rows;
    const auto shape = [&](int i) {
        return Shape{offsets[i + 1] - offsets[i], upperBegin[i] - offsets[i]};
    };
    for (int t = 0; t < tiles; ++t) {
        // Greedy: each group as many lanes as keep one shape and two runs per row.
        for (int first = 0, end; first < kTile; first = end) {
            const Shape own = shape(kTile * t + first);
            const bool vector = own.bonds > 0 && own.bonds <= kMostBonds;
            end = first + 1;
            if (vector && rows.start(offsets, slotOf, kTile * t + first, first, own.bonds))
                while (end < kTile && shape(kTile * t + end) == own &&
                       rows.extend(offsets, slotOf, kTile * t + end, end))
                    ++end;
            Group group{std::uint8_t(first), std::uint8_t(end), 0, std::uint8_t(own.lower), -1};
            if (vector && end - first >= kFewestLanes) {
                group.bonds = std::uint8_t(own.bonds), group.rowFirst = int(s.rows.size());
                group.regular = 2 * own.lower == own.bonds;
                for (int k = 0; k < own.bonds; ++k) {
                    const unsigned lanes = ((1u << (end - first)) - 1u) << first;
                    const int split = rows.split[k] < 0 ? end : rows.split[k];
                    s.rows.push_back(
                        {rows.a[k], rows.b[k], std::uint8_t(lanes & ((1u << split) - 1u))});
                    group.regular = group.regular && s.rows.back().fromA == lanes;
                }
            }
            s.groups.push_back(group);
        }
        const int made = int(s.groups.size()) - s.groupFirst[t];
        const Group& first = s.groups[s.groupFirst[t]];
        const bool whole = made == 1 && first.endLane == kTile && first.bonds > 0;
        const int before = int(s.unionRows.size());
        if (!whole && partners && unionOf(offsets, upperBegin, slotOf, partners, t, s.unionRows)) {
            const int rows = int(s.unionRows.size()) - before;
            s.groups.resize(s.groupFirst[t]);
            s.groups.push_back(
                Group{0, std::uint8_t(kTile), std::uint8_t(rows), kUnion, before, false});
        }
        s.groupFirst[t + 1] = int(s.groups.size());
    }
    return s;
}

namespace {

/// The slots of directed bond b's pair: x, y slotStep() after, z twice that.
inline const double* slotOf(const PairGather& g, int b) {
    return g.pairForce +
           (g.rows ? std::size_t(g.pairOf[b]) : slotAt(unsigned(g.pairOf[b]) & g.slotMask, false));
}

void gatherParticle(const PairGather& g, int i) {
    const int stride = g.rows ? g.stride : slotStride(false);
    double sum[3] = {0.0, 0.0, 0.0};
    for (int b = g.offsets[i]; b < g.upperBegin[i]; ++b)
        if (g.alive[b])
            for (int k = 0; k < 3; ++k) sum[k] -= slotOf(g, b)[stride * k];
    for (int b = g.upperBegin[i]; b < g.offsets[i + 1]; ++b)
        if (g.alive[b])
            for (int k = 0; k < 3; ++k) sum[k] += slotOf(g, b)[stride * k];
    double* force = g.forceOf(i);
    for (int k = 0; k < 3; ++k) force[k] = sum[k];
}

void gatherLoop(const PairGather& g, int begin, int end) {
    for (int i = begin; i < end; ++i) gatherParticle(g, i);
}

#if defined(__x86_64__)
// Eight lanes: simdWidth() is 8 only with AVX-512 F and BW and BMI2.
#define REND_TILE_TARGET gnu::target("avx2,avx512f,avx512bw,bmi2")

/// Which of a group's bonds live, bit k of its lane l at l * bonds + k: a 64-byte load per word
/// of lanesPerWordOf() lanes (eight lanes of up to eight bonds in one).
struct GroupLife {
    std::uint64_t flags[kTile] = {}, stride = 0;
    int lanesPerWord, words;

    [[REND_TILE_TARGET]] static std::uint64_t word(const std::uint8_t* alive, int bytes) {
        const __mmask64 in = bytes >= 64 ? ~__mmask64(0) : (__mmask64(1) << bytes) - 1;
        const __m512i loaded = _mm512_maskz_loadu_epi8(in, alive);
        return _mm512_test_epi8_mask(loaded, loaded);
    }
    [[REND_TILE_TARGET]] GroupLife(const std::uint8_t* alive, int bonds, int lanes) {
        lanesPerWord = lanesPerWordOf(bonds, lanes);
        words = (lanes + lanesPerWord - 1) / lanesPerWord;
        for (int l = 0; l < lanesPerWord; ++l) stride |= std::uint64_t(1) << (l * bonds);
        for (int w = 0; w < words; ++w)
            flags[w] = word(alive + w * lanesPerWord * bonds,
                            std::min(lanesPerWord, lanes - w * lanesPerWord) * bonds);
    }
    /// Bit l: the group's lane l's k-th bond lives.
    [[REND_TILE_TARGET]] unsigned of(int k) const {
        const std::uint64_t at = stride << k;
        unsigned bits = 0;
        for (int w = 0; w < words; ++w)
            bits |= unsigned(_pext_u64(flags[w], at)) << (w * lanesPerWord);
        return bits;
    }
};

/// One row's x (or y, z: the stride after) of its lanes: those of run A and those of run B, one
/// masked load each. `a` and `b` point at the slots lane 0 would have in each run (a ring has
/// kPairTile doubles before it); other lanes are zero.
[[REND_TILE_TARGET]] inline __m512d rowLanes(const double* a, const double* b, __mmask8 fromA,
                                             __mmask8 fromB) {
    return _mm512_mask_loadu_pd(_mm512_maskz_loadu_pd(fromA, a), fromB, b);
}

/// Where the 24 doubles of x y z per particle come from: per part of eight, the lane of x (or 8
/// + the lane of y), the lane of z, and which are z's.
struct Interleave {
    long long fromXY[3][8], fromZ[3][8];
    unsigned isZ[3];
};
constexpr Interleave kInterleave = [] {
    Interleave m{};
    for (int q = 0; q < 3 * kTile; ++q) {
        const int part = q / 8, p = q % 8, component = q % 3, lane = q / 3;
        m.fromXY[part][p] = component == 1 ? 8 + lane : lane, m.fromZ[part][p] = lane;
        if (component == 2) m.isZ[part] |= 1u << p;
    }
    return m;
}();

/// Eight particles' x y z from their lanes: three stores, around the caches where `stream`
/// (out then lies on a 64-byte line).
[[REND_TILE_TARGET]] inline void storeParticles(double* out, __m512d x, __m512d y, __m512d z,
                                                bool stream) {
    for (int part = 0; part < 3; ++part) {
        const __m512d xy =
            _mm512_permutex2var_pd(x, _mm512_loadu_si512(kInterleave.fromXY[part]), y);
        const __m512d three = _mm512_mask_permutexvar_pd(
            xy, __mmask8(kInterleave.isZ[part]), _mm512_loadu_si512(kInterleave.fromZ[part]), z);
        if (stream)
            _mm512_stream_pd(out + 8 * part, three);
        else
            _mm512_storeu_pd(out + 8 * part, three);
    }
}

struct Lanes3 {
    __m512d x, y, z;
};

/// A group's row's terms added to (or taken from) each living lane's sums; `first` is the
/// group's first lane, `lanes` all of its lanes.
[[REND_TILE_TARGET]] inline void addRow(const PairGather& g, const PairSumTiles& s, int row,
                                        int first, __mmask8 lanes, unsigned living, bool minus,
                                        Lanes3& sum) {
    const PairSumTiles::Row& r = s.rows[row];
    const double *a = g.pairForce + r.atA, *b = g.pairForce + r.atB;
    const __mmask8 fromA = r.fromA, fromB = __mmask8(lanes & ~fromA);
    const __mmask8 on = __mmask8(living);
    __m512d fx, fy, fz;
    const int y = g.stride, z = 2 * g.stride;
    if (fromA == 0xff) {  // one run: an upper copy's row, or a lower one's inside a lattice
        fx = _mm512_loadu_pd(a), fy = _mm512_loadu_pd(a + y), fz = _mm512_loadu_pd(a + z);
    } else {
        fx = rowLanes(a, b, fromA, fromB), fy = rowLanes(a + y, b + y, fromA, fromB);
        fz = rowLanes(a + z, b + z, fromA, fromB);
    }
    if (minus) {
        sum.x = _mm512_mask_sub_pd(sum.x, on, sum.x, fx);
        sum.y = _mm512_mask_sub_pd(sum.y, on, sum.y, fy);
        sum.z = _mm512_mask_sub_pd(sum.z, on, sum.z, fz);
    } else {
        sum.x = _mm512_mask_add_pd(sum.x, on, sum.x, fx);
        sum.y = _mm512_mask_add_pd(sum.y, on, sum.y, fy);
        sum.z = _mm512_mask_add_pd(sum.z, on, sum.z, fz);
    }
}

/// A row's x (or y, z: `at` after) of all eight lanes, from one run or two: plain loads (a ring
/// has kPairTile readable doubles before and after it) and a blend.
[[REND_TILE_TARGET]] inline __m512d wholeRow(const double* a, const double* b, __mmask8 fromA,
                                             int at) {
    if (fromA == 0xff) return _mm512_loadu_pd(a + at);
    return _mm512_mask_blend_pd(fromA, _mm512_loadu_pd(b + at), _mm512_loadu_pd(a + at));
}

/// A tile of one group of eight lanes with at most eight bonds each (a regular lattice's
/// interior): its rows' pointers and its life flags (one 64-byte load) kept in registers;
/// compiled for each count of bonds, so that its loop unrolls, and for regular groups (almost
/// every tile in rows by k), so that it is straight code: the branches on each row's runs and
/// on whether it is a lower copy, predicted or not, cost 0.4 of the sums' 2.7 ns per particle
/// (crack_path_sources at 10^4, linear, 10.69 -> 10.31 with the first alone, timing only).
/// kLiving: every bond of the tile lives (PairGather::tileLiving), so its flags are not read
/// and every lane adds (the masked adds' bits with every lane on).
template <int kBonds, bool kRegular, bool kLiving>
[[REND_TILE_TARGET]] void sumWholeTile(const PairGather& g, const PairSumTiles::Row* row,
                                       int lowerCopies, const std::uint8_t* alive, double* out,
                                       bool stream) {
    const int lower = kRegular ? kBonds / 2 : lowerCopies;
    constexpr __mmask64 kFlags =
        kBonds == kTile ? ~__mmask64(0) : (__mmask64(1) << (kTile * kBonds)) - 1;
    constexpr std::uint64_t kStride = [] {  // bit 0 of each lane's flags
        std::uint64_t stride = 0;
        for (int l = 0; l < kTile; ++l) stride |= std::uint64_t(1) << (l * kBonds);
        return stride;
    }();
    std::uint64_t life = ~std::uint64_t(0);
    if constexpr (!kLiving) {
        const __m512i bytes = _mm512_maskz_loadu_epi8(kFlags, alive);
        life = _mm512_test_epi8_mask(bytes, bytes);
    }
    __m512d x = _mm512_setzero_pd(), y = x, z = x;
#pragma GCC unroll 8
    for (int k = 0; k < kBonds; ++k) {
        const double *a = g.pairForce + row[k].atA, *b = g.pairForce + row[k].atB;
        const __mmask8 fromA = kRegular ? 0xff : row[k].fromA;
        const __mmask8 on = kLiving ? __mmask8(0xff) : __mmask8(_pext_u64(life, kStride << k));
        const __m512d fx = wholeRow(a, b, fromA, 0), fy = wholeRow(a, b, fromA, g.stride);
        const __m512d fz = wholeRow(a, b, fromA, 2 * g.stride);
        if (k < lower) {
            x = _mm512_mask_sub_pd(x, on, x, fx), y = _mm512_mask_sub_pd(y, on, y, fy);
            z = _mm512_mask_sub_pd(z, on, z, fz);
        } else {
            x = _mm512_mask_add_pd(x, on, x, fx), y = _mm512_mask_add_pd(y, on, y, fy);
            z = _mm512_mask_add_pd(z, on, z, fz);
        }
    }
    storeParticles(out, x, y, z, stream);
}

/// A union row's x (or y, z: `at` after) of its lanes: run A's load, runs B and C blended in.
[[REND_TILE_TARGET]] inline __m512d unionLanes(const double* pairForce,
                                               const PairSumTiles::UnionRow& r, int at) {
    __m512d v = _mm512_loadu_pd(pairForce + r.at[0] + at);
    if (r.from[1] != 0)
        v = _mm512_mask_blend_pd(r.from[1], v, _mm512_loadu_pd(pairForce + r.at[1] + at));
    if (r.from[2] != 0)
        v = _mm512_mask_blend_pd(r.from[2], v, _mm512_loadu_pd(pairForce + r.at[2] + at));
    return v;
}

/// A tile of lanes with different bonds (PairSumTiles::kUnion), as one group: its rows in
/// increasing offset, each lane's existing bonds in its own order, the others masked off.
[[REND_TILE_TARGET]] void sumUnionTile(const PairGather& g, const PairSumTiles& s,
                                       const PairSumTiles::Group& one, int t, bool stream) {
    const int base = g.offsets[kTile * t], flags = g.offsets[kTile * (t + 1)] - base;
    const __mmask64 in = flags >= 64 ? ~__mmask64(0) : (__mmask64(1) << flags) - 1;
    const __m512i bytes = _mm512_maskz_loadu_epi8(in, g.alive + base);
    const std::uint64_t life = _mm512_test_epi8_mask(bytes, bytes);
    __m512d x = _mm512_setzero_pd(), y = x, z = x;
    for (int q = one.rowFirst; q < one.rowFirst + one.bonds; ++q) {
        const PairSumTiles::UnionRow& r = s.unionRows[q];
        const __mmask8 on = __mmask8(_pdep_u64(_pext_u64(life, r.select), r.having));
        const __m512d fx = unionLanes(g.pairForce, r, 0);
        const __m512d fy = unionLanes(g.pairForce, r, g.stride);
        const __m512d fz = unionLanes(g.pairForce, r, 2 * g.stride);
        if (r.minus) {
            x = _mm512_mask_sub_pd(x, on, x, fx), y = _mm512_mask_sub_pd(y, on, y, fy);
            z = _mm512_mask_sub_pd(z, on, z, fz);
        } else {
            x = _mm512_mask_add_pd(x, on, x, fx), y = _mm512_mask_add_pd(y, on, y, fy);
            z = _mm512_mask_add_pd(z, on, z, fz);
        }
    }
    storeParticles(g.forceOf(kTile * t), x, y, z, stream);
}

/// The sums of tile t's eight particles: each lane's terms in its own bond order, group by
/// group (a group without rows one particle at a time, after the tile's store).
[[REND_TILE_TARGET]] void sumTile(const PairGather& g, const PairSumTiles& s, int t, bool stream) {
    if (const PairSumTiles::Group& one = s.groups[s.groupFirst[t]]; one.endLane == kTile) {
        if (one.lower == PairSumTiles::kUnion) return sumUnionTile(g, s, one, t, stream);
        const PairSumTiles::Row* rows = s.rows.data() + one.rowFirst;
        const std::uint8_t* alive = g.alive + g.offsets[kTile * t];
        double* out = g.forceOf(kTile * t);
        // The square lattice's 8, hexagonal's 6; whether all live, a byte a tile where the
        // caller keeps them.
        const bool living = g.tileLiving && g.tileLiving[t] != 0;
        switch (one.bonds + (one.regular ? 100 : 0) + (living ? 1000 : 0)) {
            case 1108:
                return sumWholeTile<8, true, true>(g, rows, one.lower, alive, out, stream);
            case 108:
                return sumWholeTile<8, true, false>(g, rows, one.lower, alive, out, stream);
            case 1008:
            case 8:
                return sumWholeTile<8, false, false>(g, rows, one.lower, alive, out, stream);
            case 1106:
                return sumWholeTile<6, true, true>(g, rows, one.lower, alive, out, stream);
            case 106:
                return sumWholeTile<6, true, false>(g, rows, one.lower, alive, out, stream);
            case 1006:
            case 6:
                return sumWholeTile<6, false, false>(g, rows, one.lower, alive, out, stream);
            default:
                break;
        }
    }
    Lanes3 sum{_mm512_setzero_pd(), _mm512_setzero_pd(), _mm512_setzero_pd()};
    unsigned alone = 0;
    for (int q = s.groupFirst[t]; q < s.groupFirst[t + 1]; ++q) {
        const PairSumTiles::Group& group = s.groups[q];
        const int first = group.firstLane, lanes = group.endLane - first;
        const unsigned mask = ((1u << lanes) - 1u) << first;
        if (group.bonds == 0) {
            alone |= mask;
            continue;
        }
        const GroupLife life(g.alive + g.offsets[kTile * t + first], group.bonds, lanes);
        int k = 0;
        for (; k < group.lower; ++k)
            addRow(g, s, group.rowFirst + k, first, __mmask8(mask), life.of(k) << first, true, sum);
        for (; k < group.bonds; ++k)
            addRow(g, s, group.rowFirst + k, first, __mmask8(mask), life.of(k) << first, false,
                   sum);
    }
    storeParticles(g.forceOf(kTile * t), sum.x, sum.y, sum.z, stream);
    for (; alone != 0; alone &= alone - 1) gatherParticle(g, kTile * t + std::countr_zero(alone));
}

/// The rows and life flags of tile t, asked for now. On a sheet that streams from memory the
/// hardware's prefetchers, following a dozen other streams, left the rows' reads waiting
/// (10^6 particles, power law: 11.8 -> 11.3 ns per particle-step; 10^4: the same).
[[REND_TILE_TARGET]] inline void prefetchTile(const PairGather& g, const PairSumTiles& s, int t) {
    const PairSumTiles::Group& first = s.groups[s.groupFirst[t]];
    if (first.lower == PairSumTiles::kUnion) {
        __builtin_prefetch(s.unionRows.data() + first.rowFirst);
    } else if (first.bonds > 0) {
        const char* rows = reinterpret_cast<const char*>(s.rows.data() + first.rowFirst);
        __builtin_prefetch(rows);
        __builtin_prefetch(rows + 64);  // a tile's eight rows: 96 bytes
    }
    if (!g.tileLiving || g.tileLiving[t] == 0) __builtin_prefetch(g.alive + g.offsets[kTile * t]);
}

[[REND_TILE_TARGET]] void gatherTiles(const PairGather& input, int begin, int end) {
    constexpr int kTilesAhead = 16;
    const PairGather g = input;  // its own copy: the force stores cannot alias it
    const PairSumTiles& s = *g.tiles;
    const int lastTile = int(s.groupFirst.size()) - 2;
    int i = begin;
    for (; i < end && i % kTile != 0; ++i) gatherParticle(g, i);
    const bool stream = writesAround(g);
    for (; i + kTile <= end; i += kTile) {
        prefetchTile(g, s, std::min(i / kTile + kTilesAhead, lastTile));
        sumTile(g, s, i / kTile, stream);
    }
    for (; i < end; ++i) gatherParticle(g, i);
    if (stream) _mm_sfence();  // the streamed stores before any other thread's reads
}

// Four lanes (AVX2): a tile of one regular group (a lattice's interior, sim/PairSums.h) whose
// bonds all live as two halves of four particles, their rows' terms in each lane's bond order:
// the same bits as one particle at a time (and as the masked rows below). One particle at a time
// (x y z 0 slots) each term waited on the one before, a chain of eight adds: on one Zen 3 core,
// crack_path_sources at 10^4, linear law, the sums' cpu-clock samples fell from 0.38 of the pair
// kernel's to 0.26; with the blow-up guard's AVX2 loop, alternate runs 32.4 -> 28.2 and 34.2 ->
// 28.9 ns per particle-step, stretch 26.4 -> 20.5 and 25.1 -> 22.3.

/// Bit k: life flag k of the 32 from `alive` is zero.
[[gnu::target("avx2")]] inline unsigned deadOf32(const std::uint8_t* alive) {
    const __m256i flags = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(alive));
    return unsigned(_mm256_movemask_epi8(_mm256_cmpeq_epi8(flags, _mm256_setzero_si256())));
}

/// Whether `count` (32 or more) life flags from `alive` are all nonzero: 32 at a time, the last
/// 32 overlapping the ones before where count is not a multiple (a hexagonal tile's 48: a
/// compiled byte loop there took a tenth of the sums' cpu-clock samples).
[[gnu::target("avx2")]] inline bool allLiving(const std::uint8_t* alive, int count) {
    unsigned dead = 0;
    int k = 0;
    for (; k + 32 <= count; k += 32) dead |= deadOf32(alive + k);
    if (k < count) dead |= deadOf32(alive + count - 32);
    return dead == 0;
}

template <int kBonds>
[[gnu::target("avx2")]] void sumRegularTileAvx2(const PairGather& g, const PairSumTiles::Row* row,
                                                double* out) {
    const double* at[kBonds];
#pragma GCC unroll 12
    for (int k = 0; k < kBonds; ++k) at[k] = g.pairForce + row[k].atA;
    __m256d sum[6];
    // x, then y, then z: each axis's offset hidden from the compiler (an empty asm), so that
    // its loads address [row + axis], the rows in registers. Bonds and axes in one unrolled
    // loop had it keep a pointer per row and axis, spilled to the stack (169 -> 149
    // instructions a tile, scripts/bench_instructions.sh).
#pragma GCC unroll 3
    for (int c = 0; c < 3; ++c) {
        std::ptrdiff_t axis = c * std::ptrdiff_t(g.stride);
        asm("" : "+r"(axis));
        __m256d low = _mm256_setzero_pd(), high = low;
#pragma GCC unroll 12
        for (int k = 0; k < kBonds; ++k) {
            const __m256d a = _mm256_loadu_pd(at[k] + axis), b = _mm256_loadu_pd(at[k] + axis + 4);
            low = k < kBonds / 2 ? _mm256_sub_pd(low, a) : _mm256_add_pd(low, a);
            high = k < kBonds / 2 ? _mm256_sub_pd(high, b) : _mm256_add_pd(high, b);
        }
        sum[2 * c] = low, sum[2 * c + 1] = high;
    }
    storeRun4(out, sum[0], sum[2], sum[4]);
    storeRun4(out + 12, sum[1], sum[3], sum[5]);
}

/// sumRegularTileAvx2 for any count of bonds (a wide horizon's 12 to 64), its rows in a loop.
[[gnu::target("avx2")]] void sumWideRegularTileAvx2(const PairGather& g,
                                                    const PairSumTiles::Row* row, int bonds,
                                                    double* out) {
    __m256d sum[6];
    for (__m256d& s : sum) s = _mm256_setzero_pd();
    const std::ptrdiff_t y = g.stride;
    for (int k = 0; k < bonds; ++k) {
        const double* a = g.pairForce + row[k].atA;
        const double* at[3] = {a, a + y, a + 2 * y};
        for (int c = 0; c < 3; ++c)
            for (int h = 0; h < 2; ++h) {
                const __m256d f = _mm256_loadu_pd(at[c] + 4 * h);
                __m256d& to = sum[2 * c + h];
                to = k < bonds / 2 ? _mm256_sub_pd(to, f) : _mm256_add_pd(to, f);
            }
    }
    storeRun4(out, sum[0], sum[2], sum[4]);
    storeRun4(out + 12, sum[1], sum[3], sum[5]);
}

// Four lanes' masks and the other tiles (sumGroupTileAvx2, sumUnionTileAvx2): a tile of one
// group whose bonds do not all live or whose rows lie in two runs, and a tile across a lattice
// row's ends, by masked rows as the AVX-512 sumTile's, each lane's terms in its bond order, a
// masked-off lane's sum left as it was (a blend, not + 0.0: -0.0 + 0.0 is +0.0): the same bits.
// One particle at a time, those tiles were half of the sums' cpu-clock samples on
// crack_path_sources at 10^4 (186 of its 1,275 tiles a step: 113 across a row's ends, 64 of one
// group not regular, 9 regular with a broken bond); by rows, the sums' fastest step on one Zen 3
// core fell from 105,000-137,000 to 89,000-92,000 TSC cycles (three runs each), the step's
// ns per particle from 22.0 to 21.7 (linear), 26.3 to 26.2 (power law), 25.8 to 25.2
// (elastoplastic; fastest of 8-12 alternate runs). The branches on a union row's runs and
// halves stay: without them, 94,000.
#define REND_TILE_AVX2 gnu::target("avx2,bmi2")

/// Bits 0-3 of `bits` as four lanes' masks.
[[REND_TILE_AVX2]] inline __m256d laneMask(unsigned bits) {
    const __m256i lane = _mm256_setr_epi64x(1, 2, 4, 8);
    const __m256i set = _mm256_and_si256(_mm256_set1_epi64x(bits), lane);
    return _mm256_castsi256_pd(_mm256_cmpeq_epi64(set, lane));
}

/// Bit k: flag k of 32 from `alive` is zero.
[[REND_TILE_AVX2]] inline std::uint64_t deadBits(const std::uint8_t* alive) {
    const __m256i flags = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(alive));
    return unsigned(_mm256_movemask_epi8(_mm256_cmpeq_epi8(flags, _mm256_setzero_si256())));
}

/// Bit k: life flag k of `count` (at most 64) from `alive` is nonzero. `readable`: 64 bytes
/// from `alive` may be read.
[[REND_TILE_AVX2]] inline std::uint64_t lifeBits(const std::uint8_t* alive, int count,
                                                 bool readable) {
    alignas(32) std::uint8_t copy[64] = {};
    if (!readable) std::memcpy(copy, alive, std::size_t(count)), alive = copy;
    const std::uint64_t living = ~(deadBits(alive) | deadBits(alive + 32) << 32);
    return count >= 64 ? living : living & ((std::uint64_t(1) << count) - 1);
}

/// Eight lanes' sums as two halves of four.
struct HalfSums {
    __m256d x[2], y[2], z[2];
};

/// sum + f (minus: sum - f) in the lanes `keep`, sum in the others.
[[REND_TILE_AVX2]] inline __m256d addTerm(__m256d sum, __m256d f, __m256d keep, bool minus) {
    return _mm256_blendv_pd(sum, minus ? _mm256_sub_pd(sum, f) : _mm256_add_pd(sum, f), keep);
}

/// Half h's terms (x, y, z) added to, or taken from, its lanes `on`.
[[REND_TILE_AVX2]] inline void addHalf(HalfSums& s, int h, __m256d fx, __m256d fy, __m256d fz,
                                       unsigned on, bool minus) {
    const __m256d keep = laneMask(on >> (4 * h));
    s.x[h] = addTerm(s.x[h], fx, keep, minus), s.y[h] = addTerm(s.y[h], fy, keep, minus);
    s.z[h] = addTerm(s.z[h], fz, keep, minus);
}

[[REND_TILE_AVX2]] inline void storeHalves(double* out, const HalfSums& s) {
    storeRun4(out, s.x[0], s.y[0], s.z[0]);
    storeRun4(out + 12, s.x[1], s.y[1], s.z[1]);
}

/// Half h's four doubles from a (the lanes of fromA) and b (the others).
[[REND_TILE_AVX2]] inline __m256d halfOf(const double* a, const double* b, unsigned fromA, int h) {
    const __m256d fromRunA = _mm256_loadu_pd(a + 4 * h);
    if (fromA == 0xff) return fromRunA;
    return _mm256_blendv_pd(_mm256_loadu_pd(b + 4 * h), fromRunA, laneMask(fromA >> (4 * h)));
}

/// The AVX-512 GroupLife's words from lifeBits(), lanesPerWordOf() lanes each (eight lanes of up
/// to eight bonds in one word).
struct GroupLifeAvx2 {
    std::uint64_t flags[kTile] = {}, stride = 0;
    int lanesPerWord, words;

    [[REND_TILE_AVX2]] GroupLifeAvx2(const PairGather& g, const PairSumTiles& s, int base,
                                     int bonds) {
        lanesPerWord = lanesPerWordOf(bonds, kTile);
        words = kTile / lanesPerWord;
        for (int l = 0; l < lanesPerWord; ++l) stride |= std::uint64_t(1) << (l * bonds);
        const int count = lanesPerWord * bonds;
        for (int w = 0, at = base; w < words; ++w, at += count)
            flags[w] = lifeBits(g.alive + at, count, at + 64 <= s.directedBonds);
    }
    /// Bit l: lane l's k-th bond lives.
    [[REND_TILE_AVX2]] unsigned of(int k) const {
        const std::uint64_t at = stride << k;
        unsigned bits = 0;
        for (int w = 0; w < words; ++w)
            bits |= unsigned(_pext_u64(flags[w], at)) << (w * lanesPerWord);
        return bits;
    }
};

/// A tile of one group of eight lanes with at most PairSumTiles::kMostBonds bonds each
/// (PairSumTiles::Group).
[[REND_TILE_AVX2]] void sumGroupTileAvx2(const PairGather& g, const PairSumTiles& s,
                                         const PairSumTiles::Group& one, int t) {
    const int bonds = one.bonds;
    const GroupLifeAvx2 life(g, s, g.offsets[kTile * t], bonds);
    HalfSums sum{};
    const int y = g.stride, z = 2 * g.stride;
    for (int k = 0; k < bonds; ++k) {
        const PairSumTiles::Row& r = s.rows[one.rowFirst + k];
        const double *a = g.pairForce + r.atA, *b = g.pairForce + r.atB;
        const unsigned on = life.of(k);
        for (int h = 0; h < 2; ++h)
            addHalf(sum, h, halfOf(a, b, r.fromA, h), halfOf(a + y, b + y, r.fromA, h),
                    halfOf(a + z, b + z, r.fromA, h), on, k < one.lower);
    }
    storeHalves(g.forceOf(kTile * t), sum);
}

/// Half h of a union row: where its lanes lie in runs A, B and C, and which lanes come from B and
/// from C (masks asked for once for the three axes).
struct UnionHalf {
    const double *a, *b, *c;
    bool fromB, fromC;
    __m256d maskB, maskC;

    [[REND_TILE_AVX2]] UnionHalf(const double* pairForce, const PairSumTiles::UnionRow& r, int h) {
        const unsigned lanesB = unsigned(r.from[1]) >> (4 * h) & 15u;
        const unsigned lanesC = unsigned(r.from[2]) >> (4 * h) & 15u;
        a = pairForce + r.at[0] + 4 * h, b = pairForce + r.at[1] + 4 * h;
        c = pairForce + r.at[2] + 4 * h;
        fromB = lanesB != 0, fromC = lanesC != 0;
        maskB = fromB ? laneMask(lanesB) : _mm256_setzero_pd();
        maskC = fromC ? laneMask(lanesC) : _mm256_setzero_pd();
    }
    /// The half's x (or y, z: `at` after): run A's load, runs B and C blended in.
    [[REND_TILE_AVX2]] __m256d at(std::ptrdiff_t axis) const {
        __m256d v = _mm256_loadu_pd(a + axis);
        if (fromB) v = _mm256_blendv_pd(v, _mm256_loadu_pd(b + axis), maskB);
        if (fromC) v = _mm256_blendv_pd(v, _mm256_loadu_pd(c + axis), maskC);
        return v;
    }
};

/// A tile across a lattice row's ends (PairSumTiles::kUnion), as sumUnionTile.
[[REND_TILE_AVX2]] void sumUnionTileAvx2(const PairGather& g, const PairSumTiles& s,
                                         const PairSumTiles::Group& one, int t) {
    const int base = g.offsets[kTile * t], flags = g.offsets[kTile * (t + 1)] - base;
    const std::uint64_t life = lifeBits(g.alive + base, flags, base + 64 <= s.directedBonds);
    const std::ptrdiff_t y = g.stride, z = 2 * y;
    HalfSums sum{};
    for (int q = one.rowFirst; q < one.rowFirst + one.bonds; ++q) {
        const PairSumTiles::UnionRow& r = s.unionRows[q];
        const unsigned on = unsigned(_pdep_u64(_pext_u64(life, r.select), r.having));
        const bool minus = r.minus;
        for (int h = 0; h < 2; ++h)
            if ((on >> (4 * h) & 15u) != 0) {
                const UnionHalf lanes(g.pairForce, r, h);
                addHalf(sum, h, lanes.at(0), lanes.at(y), lanes.at(z), on, minus);
            }
    }
    storeHalves(g.forceOf(kTile * t), sum);
}

/// Tile t at four lanes: a regular group whose bonds all live by its rows, unmasked; a tile of
/// one group of at most PairSumTiles::kMostBonds bonds, or across a row's ends, by masked rows;
/// else one particle at a time. (Groups of 9-16 bonds went one particle at a time before: on a
/// square sheet of horizon 2.2, 12 bonds, crack_path_sources at 10^4, linear, the sums were 30%
/// of a step's cpu-clock samples; by rows the step went 44.0 -> 33.6 ns per particle on one Zen
/// 3 core, fastest of six alternate runs, the same bits.)
[[REND_TILE_AVX2]] void sumTileAvx2(const PairGather& g, const PairSumTiles& s, int t) {
    const PairSumTiles::Group& one = s.groups[s.groupFirst[t]];
    const int base = kTile * t;
    if (one.endLane == kTile) {
        if (one.lower == PairSumTiles::kUnion) return sumUnionTileAvx2(g, s, one, t);
        // Whether its bonds all live: a byte per tile where the caller keeps them (about 35
        // instructions a tile to read its flags: 4 of stretch's ~123 a particle-step).
        const bool living = g.tileLiving ? g.tileLiving[t] != 0
                                         : allLiving(g.alive + g.offsets[base], kTile * one.bonds);
        if (one.regular && one.bonds >= 4 && living) {
            const PairSumTiles::Row* rows = s.rows.data() + one.rowFirst;
            if (one.bonds == 8) return sumRegularTileAvx2<8>(g, rows, g.forceOf(base));
            if (one.bonds == 12) return sumRegularTileAvx2<12>(g, rows, g.forceOf(base));
            if (one.bonds == 6) return sumRegularTileAvx2<6>(g, rows, g.forceOf(base));
            return sumWideRegularTileAvx2(g, rows, one.bonds, g.forceOf(base));
        }
        if (one.bonds > 0 && one.bonds <= PairSumTiles::kMostBonds)
            return sumGroupTileAvx2(g, s, one, t);
    }
    for (int i = base; i < base + kTile; ++i) gatherParticle(g, i);
}

[[REND_TILE_AVX2]] void gatherTilesAvx2(const PairGather& g, int begin, int end) {
    const PairSumTiles& s = *g.tiles;
    int i = begin;
    for (; i < end && i % kTile != 0; ++i) gatherParticle(g, i);
    for (; i + kTile <= end; i += kTile) sumTileAvx2(g, s, i / kTile);
    for (; i < end; ++i) gatherParticle(g, i);
}
#endif

}  // namespace

void gatherPairForces(const PairGather& g, int begin, int end) {
#if defined(__x86_64__)
    if (g.rows && g.tiles && simdWidth() == 8) return gatherTiles(g, begin, end);
    static const bool bmi2 = __builtin_cpu_supports("bmi2");
    if (g.rows && g.tiles && simdWidth() == 4 && bmi2) return gatherTilesAvx2(g, begin, end);
#endif
    gatherLoop(g, begin, end);
}

bool writesAround(const PairGather& g) {
    return g.stream && g.rows && g.tiles && simdWidth() == 8 &&
           reinterpret_cast<std::uintptr_t>(g.force) % 64 == 0;
}

bool streamsForces(long long particles) {
    constexpr long long kStepBytes = 256;  // per particle
    static const long long cache = lastLevelCacheBytes();
    return particles * kStepBytes > cache;
}

// The largest cache the kernel lists for CPU 0 (what lscpu prints: the L3 this core shares),
// else 32 MiB. glibc's sysconf(_SC_LEVEL3_CACHE_SIZE) can report the whole package's (384 MiB
// on this VM's EPYC, against 32 MiB per core complex).
long long lastLevelCacheBytes() {
    long long largest = 0;
    for (int index = 0; index < 8; ++index) {
        std::ifstream file("/sys/devices/system/cpu/cpu0/cache/index" + std::to_string(index) +
                           "/size");
        long long size = 0;
        char unit = 0;
        if (!(file >> size)) break;
        file >> unit;
        const long long bytes = unit == 'K' ? size << 10 : unit == 'M' ? size << 20 : size;
        largest = std::max(largest, bytes);
    }
    return largest > 0 ? largest : 32ll << 20;
}

}  // namespace rend::sim
