#pragma once
// Eight consecutive particles' x, y and z (24 doubles, x0 y0 z0 x1 ... z7) as three AVX-512
// vectors: three loads, six permutes; four as three AVX2 vectors, and back. For the kernels
// compiled for AVX2 and AVX-512 (sim/PairKernels.cpp, sim/PairSums.cpp, sim/StepKernels.cpp);
// include it only there.

#include <immintrin.h>

namespace rend::sim {

[[gnu::always_inline, gnu::target("avx2,avx512f")]] inline __m512d pickLanes(__m512d low,
                                                                             __m512d high,
                                                                             __m512i from) {
    return _mm512_permutex2var_pd(low, from, high);
}

/// Eight particles' x y z (a = x0 y0 z0 x1 y1 z1 x2 y2, b and c the next sixteen) as three
/// lanes.
[[gnu::always_inline, gnu::target("avx2,avx512f")]] inline void splitRun8(__m512d a, __m512d b,
                                                                          __m512d c, __m512d& x,
                                                                          __m512d& y, __m512d& z) {
    x = pickLanes(pickLanes(a, b, _mm512_setr_epi64(0, 3, 6, 9, 12, 15, 0, 0)), c,
                  _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 10, 13));
    y = pickLanes(pickLanes(a, b, _mm512_setr_epi64(1, 4, 7, 10, 13, 0, 0, 0)), c,
                  _mm512_setr_epi64(0, 1, 2, 3, 4, 8, 11, 14));
    z = pickLanes(pickLanes(a, b, _mm512_setr_epi64(2, 5, 8, 11, 14, 0, 0, 0)), c,
                  _mm512_setr_epi64(0, 1, 2, 3, 4, 9, 12, 15));
}

[[gnu::always_inline, gnu::target("avx2,avx512f")]] inline void loadRun8(const double* p,
                                                                         __m512d& x, __m512d& y,
                                                                         __m512d& z) {
    splitRun8(_mm512_loadu_pd(p), _mm512_loadu_pd(p + 8), _mm512_loadu_pd(p + 16), x, y, z);
}

// Four particles' x y z (x0 y0 z0 x1 y1 z1 x2 y2 z2 x3 y3 z3) as three lanes: each 128-bit half
// beside the half six doubles on (a = x0 y0 x2 y2, b = z0 x1 z2 x3, c = y1 z1 y3 z3), then three
// shuffles within 128-bit lanes. Three loads, six permutes and blends across lanes before: three
// instructions more for four particles.
[[gnu::always_inline, gnu::target("avx2")]] inline void splitPairs(__m256d a, __m256d b, __m256d c,
                                                                   __m256d& x, __m256d& y,
                                                                   __m256d& z) {
    x = _mm256_blend_pd(a, b, 0b1010);
    y = _mm256_shuffle_pd(a, c, 0b0101);
    z = _mm256_blend_pd(b, c, 0b1010);
}

/// Four particles' x y z (a = x0 y0 z0 x1, b = y1 z1 x2 y2, c = z2 x3 y3 z3) as three lanes.
[[gnu::always_inline, gnu::target("avx2")]] inline void splitRun4(__m256d a, __m256d b, __m256d c,
                                                                  __m256d& x, __m256d& y,
                                                                  __m256d& z) {
    splitPairs(_mm256_blend_pd(a, b, 0b1100), _mm256_permute2f128_pd(a, c, 0x21),
               _mm256_blend_pd(b, c, 0b1100), x, y, z);
}

/// The 128 bits at p and at q as one vector's halves.
[[gnu::always_inline, gnu::target("avx2")]] inline __m256d loadHalves(const double* p,
                                                                      const double* q) {
    return _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p)), _mm_loadu_pd(q), 1);
}

[[gnu::always_inline, gnu::target("avx2")]] inline void loadRun4(const double* p, __m256d& x,
                                                                 __m256d& y, __m256d& z) {
    splitPairs(loadHalves(p, p + 6), loadHalves(p + 2, p + 8), loadHalves(p + 4, p + 10), x, y, z);
}

/// Four particles' x y z from their lanes (loadRun4's inverse): three stores.
[[gnu::always_inline, gnu::target("avx2")]] inline void storeRun4(double* out, __m256d x, __m256d y,
                                                                  __m256d z) {
    const __m256d a = _mm256_unpacklo_pd(x, y);       // x0 y0 x2 y2
    const __m256d b = _mm256_blend_pd(z, x, 0b1010);  // z0 x1 z2 x3
    const __m256d c = _mm256_unpackhi_pd(y, z);       // y1 z1 y3 z3
    _mm256_storeu_pd(out, _mm256_permute2f128_pd(a, b, 0x20));
    _mm256_storeu_pd(out + 4, _mm256_blend_pd(c, a, 0b1100));
    _mm256_storeu_pd(out + 8, _mm256_permute2f128_pd(b, c, 0x31));
}

}  // namespace rend::sim
