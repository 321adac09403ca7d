#include "sim/DiffusionKernels.h"

#include <immintrin.h>

#include <algorithm>
#include <cstring>

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
    d.tileBegin.assign(tiles + 1, 0);
    for (int t = 0; t < tiles; ++t) {
        int most = 0;
        for (int lane = 0; lane < kTile; ++lane) most = std::max(most, count(kTile * t + lane));
        d.tileBegin[t + 1] = d.tileBegin[t] + kTile * most;
    }
    const int slots = d.tileBegin[tiles];
    d.partner.assign(slots, 0), d.bond.assign(slots, -1), d.rate.assign(slots, 0.0);
    d.living.assign(slots, 0);
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
    return d;
}

void DiffusionTiles::refresh(const std::uint8_t* alive, std::uint64_t version) {
    if (version == livingVersion) return;
    for (std::size_t u = 0; u < bond.size(); ++u) living[u] = bond[u] >= 0 && alive[bond[u]];
    livingVersion = version;
}

void diffuseParticle(const DiffusionTiles& d, const double* theta, double* next, double dt, int i) {
    constexpr int kTile = DiffusionTiles::kTile;
    const int t = i / kTile;
    const double own = theta[i];
    double flux = 0.0;
    for (int u = d.tileBegin[t] + i % kTile; u < d.tileBegin[t + 1]; u += kTile)
        if (d.living[u]) flux += d.rate[u] * (theta[d.partner[u]] - own);
    next[i] = own + dt * flux;
}

namespace {

void diffuseTile(const DiffusionTiles& d, const double* theta, double* next, double dt, int t) {
    for (int lane = 0; lane < DiffusionTiles::kTile; ++lane)
        diffuseParticle(d, theta, next, dt, DiffusionTiles::kTile * t + lane);
}

#if defined(__x86_64__)
/// Whether index[0..lanes) are consecutive.
[[gnu::target("avx2")]] inline bool consecutive8(const int* index) {
    const __m256i at = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(index));
    const __m256i run =
        _mm256_add_epi32(_mm256_set1_epi32(index[0]), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
    return unsigned(_mm256_movemask_epi8(_mm256_cmpeq_epi32(at, run))) == 0xffffffffu;
}

[[gnu::target("avx2,avx512f")]] void diffuseTilesAvx512(const DiffusionTiles& d,
                                                        const double* theta, double* next,
                                                        double dt, int firstTile, int lastTile) {
    const int* __restrict begin = d.tileBegin.data();
    const int* __restrict partner = d.partner.data();
    const double* __restrict rate = d.rate.data();
    const std::uint8_t* __restrict living = d.living.data();
    const __m512d step = _mm512_set1_pd(dt);
    for (int t = firstTile; t < lastTile; ++t) {
        const __m512d own = _mm512_loadu_pd(theta + 8 * t);
        __m512d flux = _mm512_setzero_pd();
        for (int u = begin[t]; u < begin[t + 1]; u += 8) {
            const __m512d other =
                consecutive8(partner + u)
                    ? _mm512_loadu_pd(theta + partner[u])
                    : _mm512_i32gather_pd(
                          _mm256_loadu_si256(reinterpret_cast<const __m256i*>(partner + u)), theta,
                          8);
            std::uint64_t bytes;
            std::memcpy(&bytes, living + u, 8);
            const __mmask8 alive = _mm512_cmpneq_epi64_mask(
                _mm512_cvtepu8_epi64(_mm_cvtsi64_si128(bytes)), _mm512_setzero_si512());
            const __m512d term =
                _mm512_mul_pd(_mm512_loadu_pd(rate + u), _mm512_sub_pd(other, own));
            flux = _mm512_mask_add_pd(flux, alive, flux, term);
        }
        _mm512_storeu_pd(next + 8 * t, _mm512_add_pd(own, _mm512_mul_pd(step, flux)));
    }
}

[[gnu::target("avx2")]] void diffuseTilesAvx2(const DiffusionTiles& d, const double* theta,
                                              double* next, double dt, int firstTile,
                                              int lastTile) {
    const int* __restrict begin = d.tileBegin.data();
    const int* __restrict partner = d.partner.data();
    const double* __restrict rate = d.rate.data();
    const std::uint8_t* __restrict living = d.living.data();
    const __m256d step = _mm256_set1_pd(dt);
    for (int t = firstTile; t < lastTile; ++t)
        for (int half = 0; half < 8; half += 4) {
            const __m256d own = _mm256_loadu_pd(theta + 8 * t + half);
            __m256d flux = _mm256_setzero_pd();
            for (int u = begin[t] + half; u < begin[t + 1]; u += 8) {
                const __m256d other = _mm256_setr_pd(theta[partner[u]], theta[partner[u + 1]],
                                                     theta[partner[u + 2]], theta[partner[u + 3]]);
                std::uint32_t bytes;
                std::memcpy(&bytes, living + u, 4);
                const __m256i wide = _mm256_cvtepu8_epi64(_mm_cvtsi32_si128(int(bytes)));
                const __m256d alive = _mm256_castsi256_pd(_mm256_xor_si256(
                    _mm256_cmpeq_epi64(wide, _mm256_setzero_si256()), _mm256_set1_epi64x(-1)));
                const __m256d term =
                    _mm256_mul_pd(_mm256_loadu_pd(rate + u), _mm256_sub_pd(other, own));
                flux = _mm256_blendv_pd(flux, _mm256_add_pd(flux, term), alive);
            }
            _mm256_storeu_pd(next + 8 * t + half, _mm256_add_pd(own, _mm256_mul_pd(step, flux)));
        }
}
#endif

}  // namespace

void diffuseTiles(const DiffusionTiles& tiles, const double* theta, double* next, double dt,
                  int firstTile, int lastTile) {
#if defined(__x86_64__)
    if (simdWidth() == 8) return diffuseTilesAvx512(tiles, theta, next, dt, firstTile, lastTile);
    if (simdWidth() == 4) return diffuseTilesAvx2(tiles, theta, next, dt, firstTile, lastTile);
#endif
    for (int t = firstTile; t < lastTile; ++t) diffuseTile(tiles, theta, next, dt, t);
}

}  // namespace rend::sim
