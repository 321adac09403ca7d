#include "sim/DiffusionKernels.h"

#include <immintrin.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <map>
#include <optional>

#include "sim/PairKernels.h"
#include "sim/PairSums.h"
#include "sim/RowSteps.h"
#include "sim/StepKernels.h"

namespace rend::sim {

namespace {

/// The partner offsets j - i of tile t's particles' bonds, each once, in increasing order; none
/// where a particle's bonds are not in increasing offset.
std::vector<int> unionOffsets(const BondFamilies& bonds, int t) {
    constexpr int kTile = DiffusionTiles::kTile;
    std::vector<int> all;
    for (int i = kTile * t; i < std::min(bonds.particleCount(), kTile * (t + 1)); ++i)
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
            if (b > bonds.offsets[i] && bonds.partners[b] <= bonds.partners[b - 1]) return {};
            all.push_back(bonds.partners[b] - i);
        }
    std::sort(all.begin(), all.end());
    all.erase(std::unique(all.begin(), all.end()), all.end());
    return all;
}

}  // namespace

// Each tile's rows: the k-th bonds of its particles side by side; or, where its particles' bonds
// differ (a lattice row's end) but span no more offsets than its most bonds, a row per offset,
// the particles without it padded (masked off, their partner in the row's run).
DiffusionTiles DiffusionTiles::build(const BondFamilies& bonds, const std::vector<double>& rate) {
    const int n = bonds.particleCount(), tiles = (n + kTile - 1) / kTile;
    const auto count = [&](int i) { return i < n ? bonds.offsets[i + 1] - bonds.offsets[i] : 0; };
    DiffusionTiles d;
    d.offsets = bonds.offsets;
    d.tileBegin.assign(tiles + 1, 0);
    for (int t = 0; t < tiles; ++t) {
        int most = 0;
        for (int lane = 0; lane < kTile; ++lane) most = std::max(most, count(kTile * t + lane));
        d.tileBegin[t + 1] = d.tileBegin[t] + kTile * most;
    }
    const int slots = d.tileBegin[tiles];
    d.partner.assign(slots, 0), d.bond.assign(slots, -1), d.rate.assign(slots, 0.0);
    for (int t = 0; t < tiles; ++t) {
        const std::vector<int> offsets = unionOffsets(bonds, t);
        const int rows = (d.tileBegin[t + 1] - d.tileBegin[t]) / kTile;
        const bool byOffset = int(offsets.size()) == rows;
        for (int lane = 0; lane < kTile; ++lane) {
            const int i = kTile * t + lane;
            int k = 0;  // the lane's next bond
            for (int q = 0, u = d.tileBegin[t] + lane; q < rows; ++q, u += kTile) {
                d.partner[u] = std::min(i, n - 1);
                if (byOffset) {  // the row of one offset: its partner, or a pad in the run
                    const int j = i + offsets[q];
                    if (j >= 0 && j < n) d.partner[u] = j;
                    if (k >= count(i) || bonds.partners[bonds.offsets[i] + k] != j) continue;
                } else if (k >= count(i)) {
                    continue;
                }
                const int b = bonds.offsets[i] + k++;
                d.partner[u] = bonds.partners[b], d.bond[u] = b, d.rate[u] = rate[b];
            }
        }
    }
    d.setUpRows();
    return d;
}

// Each row's run and rate class. A pad's rate does not count (its lane is masked off): it takes
// the row's first bond's for the steps.
void DiffusionTiles::setUpRows() {
    const int rows = int(partner.size()) / kTile;
    rowRun.assign(rows, -1), rowClass.assign(rows, -1), rateSteps.assign(partner.size(), 0);
    livingRows.assign(rows, 0);
    classRate.clear(), classUnit.clear();
    std::map<std::uint64_t, int> classes;
    for (int row = 0; row < rows; ++row) {
        const int u = kTile * row;
        bool run = true;
        for (int l = 1; l < kTile; ++l) run = run && partner[u + l] == partner[u] + l;
        if (run) rowRun[row] = partner[u];
        double values[kTile];
        int real = -1;
        for (int l = 0; l < kTile && real < 0; ++l)
            if (bond[u + l] >= 0) real = l;
        if (real < 0) continue;  // only pads: the per-slot rates (zeros), never summed
        for (int l = 0; l < kTile; ++l) values[l] = rate[u + (bond[u + l] >= 0 ? l : real)];
        const std::optional<RowSteps> steps = rowSteps(values, &rateSteps[u]);
        if (!steps) continue;
        const auto [at, added] = classes.try_emplace(std::bit_cast<std::uint64_t>(steps->smallest),
                                                     int(classRate.size()));
        if (added) classRate.push_back(steps->smallest), classUnit.push_back(steps->unit);
        rowClass[row] = steps->stepped ? kSteppedRate - at->second : at->second;
    }
    const int tiles = int(tileBegin.size()) - 1;
    plainTile.assign(std::max(tiles, 0), 0);
    for (int t = 0; t < tiles; ++t) {
        const int first = tileBegin[t] / kTile, end = tileBegin[t + 1] / kTile;
        const int rows = end - first;
        bool plain = rows > 0 && rows <= 255;
        for (int row = first; row < end && plain; ++row)
            plain = rowRun[row] >= 0 && rowClass[row] >= 0;
        plainTile[t] = plain ? std::uint8_t(rows) : 0;
    }
}

int DiffusionTiles::runRows() const {
    return int(std::count_if(rowRun.begin(), rowRun.end(), [](int r) { return r >= 0; }));
}

int DiffusionTiles::classedRows() const {
    return int(std::count_if(rowClass.begin(), rowClass.end(), [](int c) { return c != -1; }));
}

void DiffusionTiles::refresh(const std::uint8_t* alive, std::uint64_t version) {
    if (version == livingVersion) return;
    for (std::size_t row = 0; row < livingRows.size(); ++row) {
        unsigned bits = 0;
        for (int l = 0; l < kTile; ++l) {
            const int b = bond[kTile * row + l];
            bits |= unsigned(b >= 0 && alive[b]) << l;
        }
        livingRows[row] = std::uint8_t(bits);
    }
    livingVersion = version;
}

// A bond's slot lies in its particle's lane of its tile, in the row of its partner's offset
// (build()): the lane's rows searched for it. A shipped foil tearing at final quality spent
// 1.7% of its samples copying every flag on each step that broke a bond.
void DiffusionTiles::refresh(const DamageState& damage) {
    if (damage.version() == livingVersion) return;
    const auto broken = damage.breaksSince(livingVersion);
    if (!broken) return refresh(damage.bondAlive().data(), damage.version());
    for (const std::array<int, 2>& both : *broken)
        for (const int b : both) {
            if (b < 0) continue;
            const int i =
                int(std::upper_bound(offsets.begin(), offsets.end(), b) - offsets.begin()) - 1;
            const int t = i / kTile;
            for (int u = tileBegin[t] + i % kTile; u < tileBegin[t + 1]; u += kTile)
                if (bond[u] == b) livingRows[u / kTile] &= std::uint8_t(~(1u << (u % kTile)));
        }
    livingVersion = damage.version();
}

void diffuseParticle(const DiffusionTiles& d, const double* theta, double* next, double dt, int i) {
    constexpr int kTile = DiffusionTiles::kTile;
    const int t = i / kTile;
    const double own = theta[i];
    double flux = 0.0;
    for (int u = d.tileBegin[t] + i % kTile; u < d.tileBegin[t + 1]; u += kTile)
        if (d.living(u)) flux += d.rate[u] * (theta[d.partner[u]] - own);
    next[i] = own + dt * flux;
}

namespace {

void diffuseTile(const DiffusionTiles& d, const double* theta, double* next, double dt, int t) {
    for (int lane = 0; lane < DiffusionTiles::kTile; ++lane)
        diffuseParticle(d, theta, next, dt, DiffusionTiles::kTile * t + lane);
}

#if defined(__x86_64__)
/// A row's rates: its class's, its class's plus each slot's steps of the unit, or its own.
[[gnu::target("avx2,avx512f")]] inline __m512d rowRates(const DiffusionTiles& d, int row) {
    const int c = d.rowClass[row], u = DiffusionTiles::kTile * row;
    if (c >= 0) return _mm512_set1_pd(d.classRate[c]);
    if (c == -1) return _mm512_loadu_pd(d.rate.data() + u);
    const int k = DiffusionTiles::kSteppedRate - c;
    const __m512d steps = _mm512_cvtepi32_pd(_mm256_cvtepu16_epi32(
        _mm_loadu_si128(reinterpret_cast<const __m128i*>(d.rateSteps.data() + u))));
    return _mm512_add_pd(_mm512_set1_pd(d.classRate[k]),
                         _mm512_mul_pd(steps, _mm512_set1_pd(d.classUnit[k])));
}

/// A plain tile (DiffusionTiles::plainTile) of kRows rows (6, 8 or 12; 0: `count` rows) eight
/// lanes wide: its rows' runs as plain loads, each row's rate from its class and its lanes'
/// life flags as the add's mask; the same terms in the same order as the loop below.
template <int kRows>
[[gnu::target("avx2,avx512f")]] inline __m512d plainTileAvx512(const DiffusionTiles& d,
                                                               const double* theta, __m512d own,
                                                               __m512d step, int t,
                                                               int count = kRows) {
    const int first = d.tileBegin[t] / 8;
    const int* __restrict run = d.rowRun.data() + first;
    const int* __restrict rowClass = d.rowClass.data() + first;
    const std::uint8_t* __restrict living = d.livingRows.data() + first;
    const double* __restrict classRate = d.classRate.data();
    __m512d flux = _mm512_setzero_pd();
    std::uint64_t lives = 0;  // eight rows' living bytes as one word
    if constexpr (kRows == 8) std::memcpy(&lives, living, sizeof lives);
#pragma GCC unroll 12
    for (int k = 0; k < (kRows > 0 ? kRows : count); ++k) {
        const __m512d term = _mm512_mul_pd(_mm512_set1_pd(classRate[rowClass[k]]),
                                           _mm512_sub_pd(_mm512_loadu_pd(theta + run[k]), own));
        const unsigned on = kRows == 8 ? unsigned(lives >> (8 * k)) : living[k];
        flux = _mm512_mask_add_pd(flux, __mmask8(on), flux, term);
    }
    return _mm512_add_pd(own, _mm512_mul_pd(step, flux));
}

/// DiffusionMeasures taken eight lanes at a time from the values stored, tile after tile, with
/// largestChange's and guardThetaAvx512's operations on the same lanes in the same order: the
/// same values.
struct MeasuresAvx512 {
    __m512d change, largest;
    int firstBad = -1;
    [[gnu::target("avx2,avx512f")]] MeasuresAvx512()
        : change(_mm512_setzero_pd()), largest(_mm512_setzero_pd()) {}
    [[gnu::always_inline, gnu::target("avx2,avx512f")]] void add(__m512d own, __m512d after,
                                                                 int t) {
        const __m512d d = _mm512_sub_pd(after, own);
        change = _mm512_max_pd(change, _mm512_max_pd(d, _mm512_sub_pd(_mm512_setzero_pd(), d)));
        const __m512d a = _mm512_abs_pd(after);
        const unsigned bad =
            _mm512_cmp_pd_mask(a, _mm512_set1_pd(std::numeric_limits<double>::max()), _CMP_NLE_UQ);
        if (bad != 0 && firstBad < 0) firstBad = 8 * t + __builtin_ctz(bad);
        largest = _mm512_max_pd(a, largest);
    }
    [[gnu::target("avx2,avx512f")]] void finish(DiffusionMeasures& m) const {
        double lanes[8];
        _mm512_storeu_pd(lanes, change);
        m.largestChange = 0.0;
        for (const double l : lanes) m.largestChange = std::max(m.largestChange, l);
        _mm512_storeu_pd(lanes, largest);
        m.theta = GuardSums{};
        for (const double l : lanes) m.theta.maxAbsTheta = std::max(m.theta.maxAbsTheta, l);
        m.theta.firstBad = firstBad;
    }
};

/// A tile by its rows, as diffuseParticle's loop over each lane's slots: each row's partners one
/// load where they are a run, else a gather, its rates by rowRates.
[[gnu::target("avx2,avx512f")]] inline __m512d rowsTileAvx512(const DiffusionTiles& d,
                                                              const double* theta, __m512d own,
                                                              __m512d step, int t) {
    const int* __restrict run = d.rowRun.data();
    __m512d flux = _mm512_setzero_pd();
    for (int row = d.tileBegin[t] / 8; row < d.tileBegin[t + 1] / 8; ++row) {
        const __m512d other =
            run[row] >= 0 ? _mm512_loadu_pd(theta + run[row])
                          : _mm512_i32gather_pd(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(
                                                    d.partner.data() + 8 * row)),
                                                theta, 8);
        const __m512d term = _mm512_mul_pd(rowRates(d, row), _mm512_sub_pd(other, own));
        flux = _mm512_mask_add_pd(flux, __mmask8(d.livingRows[row]), flux, term);
    }
    return _mm512_add_pd(own, _mm512_mul_pd(step, flux));
}

template <bool kMeasure>
[[gnu::target("avx2,avx512f")]] void diffuseTilesAvx512(const DiffusionTiles& d,
                                                        const double* theta, double* next,
                                                        double dt, int firstTile, int lastTile,
                                                        bool around, DiffusionMeasures* measures) {
    const std::uint8_t* __restrict plain = d.plainTile.data();
    const __m512d step = _mm512_set1_pd(dt);
    const bool stream = around && (std::uintptr_t(next) & 63) == 0;
    MeasuresAvx512 taken;
    for (int t = firstTile; t < lastTile; ++t) {
        const __m512d own = _mm512_loadu_pd(theta + 8 * t);
        __m512d after;
        // Six rows are the hexagonal sheets' (every shipped scene's), eight the square's, twelve
        // a square sheet's of horizon 2.2. Only eight had a path of their own here before; the
        // others went by rows, testing each row's run and class (crack_path_sources on its
        // hexagonal lattice at 10^4, alternate spans: linear 6.51 / 6.51 -> 6.33 / 6.34 ns per
        // particle-step, elastoplastic 8.43 / 8.27 -> 8.09 / 8.22, the same bits).
        switch (plain[t]) {
            case 6:
                after = plainTileAvx512<6>(d, theta, own, step, t);
                break;
            case 8:
                after = plainTileAvx512<8>(d, theta, own, step, t);
                break;
            case 12:
                after = plainTileAvx512<12>(d, theta, own, step, t);
                break;
            case 0:
                after = rowsTileAvx512(d, theta, own, step, t);
                break;
            default:
                after = plainTileAvx512<0>(d, theta, own, step, t, plain[t]);
                break;
        }
        if (stream)
            _mm512_stream_pd(next + 8 * t, after);
        else
            _mm512_storeu_pd(next + 8 * t, after);
        if constexpr (kMeasure) taken.add(own, after, t);
    }
    if (stream) _mm_sfence();
    if constexpr (kMeasure) taken.finish(*measures);
}

/// Whether the kRows (6, 8 or 12) bytes from `rows` are all 0xff: read as whole words each
/// compared on its own. (Copied into one word on the stack, 4 + 2 bytes stored and 8 loaded
/// could not be forwarded: the load waited for the stores, half of diffusion's cpu-clock
/// samples on a hexagonal sheet.)
/// kRows 0: `count` rows, eight bytes at a time.
template <int kRows>
inline bool allRowsLive(const std::uint8_t* rows, int count) {
    static_assert(kRows == 0 || kRows == 6 || kRows == 8 || kRows == 12);
    const auto all = [rows]<class Word>(int at, Word) {
        Word w;
        std::memcpy(&w, rows + at, sizeof w);
        return w == Word(~Word(0));
    };
    if constexpr (kRows == 6) return all(0, std::uint32_t()) && all(4, std::uint16_t());
    if constexpr (kRows == 8) return all(0, std::uint64_t());
    if constexpr (kRows == 12) return all(0, std::uint64_t()) && all(8, std::uint32_t());
    int k = 0;
    for (; k + 8 <= count; k += 8)
        if (!all(k, std::uint64_t())) return false;
    for (; k < count; ++k)
        if (rows[k] != 0xff) return false;
    return true;
}

// A plain tile (DiffusionTiles::plainTile) of kRows rows in two halves of four lanes: its rows'
// runs as plain loads, each row's rate from its class once for both; the same terms in the
// same order as the loop below, which reads each slot's partner and rate (REND_SIMD=avx2, the
// diffusion alone, crack_path_sources, linear, pinned: 2.66 -> 1.52 ns per particle-step at
// 10^4, 5.27 -> 1.66 at 10^6). Six rows are the hexagonal sheets' (every shipped scene's),
// twelve a square sheet's of horizon 2.2; taking them here rather than by the loop below took
// crack_path_sources on its hexagonal lattice at 10^4 (linear, one Zen 3 core, fastest of eight
// alternate runs) from 19.3 to 18.1 ns per particle-step, the same bits. kRows 0: a wider
// horizon's `count` rows, in a loop (a square sheet of horizon 3, 28 rows: by the loop below,
// diffusion was a quarter of a step's instructions).
/// Lanes 0-3 of a mask, all bits set where bit l of the index is (four lanes' life flags).
struct alignas(32) LaneMasks {
    std::uint64_t lanes[16][4];
    constexpr LaneMasks() : lanes() {
        for (int bits = 0; bits < 16; ++bits)
            for (int l = 0; l < 4; ++l) lanes[bits][l] = (bits >> l & 1) ? ~std::uint64_t(0) : 0;
    }
};
constexpr LaneMasks kLaneMasks;

/// diffusePlainTile's tiles with a dead bond: each row's terms under its lanes' life flags. A
/// function of its own: inline, the compiler computed both paths' common terms before the
/// branch between them, and kept eight rows' terms on the stack (157 -> 119 instructions a
/// square tile, scripts/bench_instructions.sh). Each half's mask is one load from a table.
template <int kRows>
[[gnu::target("avx2"), gnu::noinline]] void diffuseMaskedPlainTile(const DiffusionTiles& d,
                                                                   const double* theta,
                                                                   double* next, __m256d step,
                                                                   int t, int count) {
    const __m256d ownLow = _mm256_loadu_pd(theta + 8 * t);
    const __m256d ownHigh = _mm256_loadu_pd(theta + 8 * t + 4);
    __m256d low = _mm256_setzero_pd(), high = low;
    const int first = d.tileBegin[t] / 8;
#pragma GCC unroll 12
    for (int k = 0; k < count; ++k) {
        const int row = first + k, lives = d.livingRows[row];
        const __m256d rate = _mm256_set1_pd(d.classRate[d.rowClass[row]]);
        const double* other = theta + d.rowRun[row];
        const __m256d aliveLow =
            _mm256_load_pd(reinterpret_cast<const double*>(kLaneMasks.lanes[lives & 15]));
        const __m256d aliveHigh =
            _mm256_load_pd(reinterpret_cast<const double*>(kLaneMasks.lanes[lives >> 4]));
        const __m256d termLow = _mm256_mul_pd(rate, _mm256_sub_pd(_mm256_loadu_pd(other), ownLow));
        const __m256d termHigh =
            _mm256_mul_pd(rate, _mm256_sub_pd(_mm256_loadu_pd(other + 4), ownHigh));
        low = _mm256_blendv_pd(low, _mm256_add_pd(low, termLow), aliveLow);
        high = _mm256_blendv_pd(high, _mm256_add_pd(high, termHigh), aliveHigh);
    }
    _mm256_storeu_pd(next + 8 * t, _mm256_add_pd(ownLow, _mm256_mul_pd(step, low)));
    _mm256_storeu_pd(next + 8 * t + 4, _mm256_add_pd(ownHigh, _mm256_mul_pd(step, high)));
}

template <int kRows>
[[gnu::target("avx2")]] inline void diffusePlainTile(const DiffusionTiles& d, const double* theta,
                                                     double* next, __m256d step, int t,
                                                     int count = kRows) {
    const int first = d.tileBegin[t] / 8;
    // Every bond lives: the same adds, without the masks (cpu-clock samples on one Zen 3 core,
    // crack_path_sources at 10^4, linear: 0.18 of the pair kernel's -> 0.14).
    if (!allRowsLive<kRows>(d.livingRows.data() + first, count))
        return diffuseMaskedPlainTile<kRows>(d, theta, next, step, t, count);
    const __m256d ownLow = _mm256_loadu_pd(theta + 8 * t);
    const __m256d ownHigh = _mm256_loadu_pd(theta + 8 * t + 4);
    __m256d low = _mm256_setzero_pd(), high = low;
#pragma GCC unroll 12
    for (int k = 0; k < count; ++k) {
        const int row = first + k;
        const __m256d rate = _mm256_set1_pd(d.classRate[d.rowClass[row]]);
        const double* other = theta + d.rowRun[row];
        low =
            _mm256_add_pd(low, _mm256_mul_pd(rate, _mm256_sub_pd(_mm256_loadu_pd(other), ownLow)));
        high = _mm256_add_pd(
            high, _mm256_mul_pd(rate, _mm256_sub_pd(_mm256_loadu_pd(other + 4), ownHigh)));
    }
    _mm256_storeu_pd(next + 8 * t, _mm256_add_pd(ownLow, _mm256_mul_pd(step, low)));
    _mm256_storeu_pd(next + 8 * t + 4, _mm256_add_pd(ownHigh, _mm256_mul_pd(step, high)));
}

/// Lanes [half, half + 4) of a row's rates, as rowRates.
[[gnu::target("avx2")]] inline __m256d rowRatesAvx2(const DiffusionTiles& d, int row, int half) {
    const int c = d.rowClass[row], u = DiffusionTiles::kTile * row + half;
    if (c >= 0) return _mm256_set1_pd(d.classRate[c]);
    if (c == -1) return _mm256_loadu_pd(d.rate.data() + u);
    const int k = DiffusionTiles::kSteppedRate - c;
    const __m256d steps = _mm256_cvtepi32_pd(
        _mm_cvtepu16_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(&d.rateSteps[u]))));
    return _mm256_add_pd(_mm256_set1_pd(d.classRate[k]),
                         _mm256_mul_pd(steps, _mm256_set1_pd(d.classUnit[k])));
}

// The other tiles (a lattice row's ends; every tile of a sheet whose particles have more than
// eight bonds) half by half, each row's partners one load where they are a run and its rates
// from its class. Each slot's partner and rate read one by one, diffusion took 10% of a step's
// cpu-clock samples on a square sheet of horizon 2.2 (12 bonds) at 10^4, crack_path_sources,
// linear, one Zen 3 core.
[[gnu::target("avx2")]] void diffuseTilesAvx2(const DiffusionTiles& d, const double* theta,
                                              double* next, double dt, int firstTile,
                                              int lastTile) {
    const int* __restrict begin = d.tileBegin.data();
    const int* __restrict partner = d.partner.data();
    const int* __restrict run = d.rowRun.data();
    const std::uint8_t* __restrict living = d.livingRows.data();
    const __m256d step = _mm256_set1_pd(dt);
    const __m256i laneBit = _mm256_setr_epi64x(1, 2, 4, 8);
    for (int t = firstTile; t < lastTile; ++t) {
        switch (d.plainTile[t]) {
            case 6:
                diffusePlainTile<6>(d, theta, next, step, t);
                continue;
            case 8:
                diffusePlainTile<8>(d, theta, next, step, t);
                continue;
            case 12:
                diffusePlainTile<12>(d, theta, next, step, t);
                continue;
            case 0:
                break;
            default:
                diffusePlainTile<0>(d, theta, next, step, t, d.plainTile[t]);
                continue;
        }
        for (int half = 0; half < 8; half += 4) {
            const __m256d own = _mm256_loadu_pd(theta + 8 * t + half);
            __m256d flux = _mm256_setzero_pd();
            for (int row = begin[t] / 8; row < begin[t + 1] / 8; ++row) {
                const int u = 8 * row + half;
                const __m256d other =
                    run[row] >= 0 ? _mm256_loadu_pd(theta + run[row] + half)
                                  : _mm256_setr_pd(theta[partner[u]], theta[partner[u + 1]],
                                                   theta[partner[u + 2]], theta[partner[u + 3]]);
                const __m256i bits = _mm256_set1_epi64x(living[row] >> half);
                const __m256d alive = _mm256_castsi256_pd(
                    _mm256_cmpeq_epi64(_mm256_and_si256(bits, laneBit), laneBit));
                const __m256d term =
                    _mm256_mul_pd(rowRatesAvx2(d, row, half), _mm256_sub_pd(other, own));
                flux = _mm256_blendv_pd(flux, _mm256_add_pd(flux, term), alive);
            }
            _mm256_storeu_pd(next + 8 * t + half, _mm256_add_pd(own, _mm256_mul_pd(step, flux)));
        }
    }
}
#endif

}  // namespace

// Past the caches, the new theta is written around them: a store that first reads its line
// read 8 bytes a particle for nothing (crack_path_sources at 10^7 particles, linear, alternate
// spans of one run: 10.54 -> 10.50 and 10.84 -> 10.69 ns per particle-step).
void diffuseTiles(const DiffusionTiles& tiles, const double* theta, double* next, double dt,
                  int firstTile, int lastTile, std::optional<bool> around,
                  DiffusionMeasures* measures) {
#if defined(__x86_64__)
    if (simdWidth() == 8) {
        const bool streams =
            around.value_or(streamsForces(8LL * (std::ssize(tiles.tileBegin) - 1)));
        if (measures)
            return diffuseTilesAvx512<true>(tiles, theta, next, dt, firstTile, lastTile, streams,
                                            measures);
        return diffuseTilesAvx512<false>(tiles, theta, next, dt, firstTile, lastTile, streams,
                                         nullptr);
    }
    if (simdWidth() == 4) {
        diffuseTilesAvx2(tiles, theta, next, dt, firstTile, lastTile);
    } else
#endif
    {
        for (int t = firstTile; t < lastTile; ++t) diffuseTile(tiles, theta, next, dt, t);
    }
    if (!measures) return;
    const int begin = 8 * firstTile, count = 8 * std::max(0, lastTile - firstTile);
    measures->largestChange = largestChange(theta + begin, next + begin, std::size_t(count));
    measures->theta = guardThetaSums(next, begin, begin + count);
}

}  // namespace rend::sim
