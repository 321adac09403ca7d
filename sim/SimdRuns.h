#pragma once
// Eight consecutive particles' x, y and z (24 doubles, x0 y0 z0 x1 ... z7) as three AVX-512
// vectors: three loads, six permutes; four as three AVX2 vectors. For the kernels compiled for
// AVX2 and AVX-512 (sim/PairKernels.cpp, sim/StepKernels.cpp); include it only there.

#include <immintrin.h>

namespace rend::sim {

[[gnu::always_inline, gnu::target("avx2,avx512f")]] inline __m512d pickLanes(__m512d low,
                                                                             __m512d high,
                                                                             __m512i from) {
    return _mm512_permutex2var_pd(low, from, high);
}

[[gnu::always_inline, gnu::target("avx2,avx512f")]] inline void loadRun8(const double* p,
                                                                         __m512d& x, __m512d& y,
                                                                         __m512d& z) {
    const __m512d a = _mm512_loadu_pd(p), b = _mm512_loadu_pd(p + 8), c = _mm512_loadu_pd(p + 16);
    x = pickLanes(pickLanes(a, b, _mm512_setr_epi64(0, 3, 6, 9, 12, 15, 0, 0)), c,
                  _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 10, 13));
    y = pickLanes(pickLanes(a, b, _mm512_setr_epi64(1, 4, 7, 10, 13, 0, 0, 0)), c,
                  _mm512_setr_epi64(0, 1, 2, 3, 4, 8, 11, 14));
    z = pickLanes(pickLanes(a, b, _mm512_setr_epi64(2, 5, 8, 11, 14, 0, 0, 0)), c,
                  _mm512_setr_epi64(0, 1, 2, 3, 4, 9, 12, 15));
}

/// Four particles' x y z (a = x0 y0 z0 x1, b = y1 z1 x2 y2, c = z2 x3 y3 z3) as three lanes.
[[gnu::always_inline, gnu::target("avx2")]] inline void splitRun4(__m256d a, __m256d b, __m256d c,
                                                                  __m256d& x, __m256d& y,
                                                                  __m256d& z) {
    x = _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(a, b, 0b0100), c, 0b0010),
                              _MM_SHUFFLE(1, 2, 3, 0));
    y = _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(a, b, 0b1001), c, 0b0100),
                              _MM_SHUFFLE(2, 3, 0, 1));
    z = _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(a, b, 0b0010), c, 0b1001),
                              _MM_SHUFFLE(3, 0, 1, 2));
}

[[gnu::always_inline, gnu::target("avx2")]] inline void loadRun4(const double* p, __m256d& x,
                                                                 __m256d& y, __m256d& z) {
    splitRun4(_mm256_loadu_pd(p), _mm256_loadu_pd(p + 4), _mm256_loadu_pd(p + 8), x, y, z);
}

}  // namespace rend::sim
