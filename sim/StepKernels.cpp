#include "sim/StepKernels.h"

#include <immintrin.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <string_view>

namespace rend::sim {
namespace {

constexpr std::int16_t kFree = -1;

/// One particle; returns whether it is free and not above the floor (NaN included).
inline bool kickDriftOne(const KickDrift& k, int i) {
    double* v = k.v + 3 * i;
    const std::int16_t c = k.constraint[i];
    if (c == kFree) {
        const double* f = k.force + 3 * i;
        for (int a = 0; a < 3; ++a)
            v[a] += k.h * (f[a] / k.mass[i] + k.gravity[a] - k.damping * v[a]);
    } else {
        for (int a = 0; a < 3; ++a) v[a] = c < 0 ? 0.0 : k.boundaryVelocity[3 * c + a];
    }
    for (int a = 0; a < 3; ++a) k.x[3 * i + a] += k.dt * v[a];
    return c == kFree && !(k.x[3 * i + 2] >= k.floor);
}

/// Whether `count` particles from `constraint` are all free (kFree is all bits set).
inline bool allFree(const std::int16_t* constraint, int count) {
    for (int k = 0; k < count; k += 4) {
        std::uint64_t tags;
        std::memcpy(&tags, constraint + k, sizeof tags);
        if (tags != ~std::uint64_t(0)) return false;
    }
    return true;
}

#if defined(__x86_64__)
// Four free particles are twelve doubles, three lanes of four: x0 y0 z0 x1 | y1 z1 x2 y2 |
// z2 x3 y3 z3, with the masses and gravity spread to match.
[[gnu::target("avx2")]] int kickDriftAvx2(const KickDrift& k, int begin, int end, bool& below) {
    const __m256d h = _mm256_set1_pd(k.h), dt = _mm256_set1_pd(k.dt);
    const __m256d damping = _mm256_set1_pd(k.damping), floor = _mm256_set1_pd(k.floor);
    const double* g = k.gravity;
    const __m256d gravity[3] = {_mm256_setr_pd(g[0], g[1], g[2], g[0]),
                                _mm256_setr_pd(g[1], g[2], g[0], g[1]),
                                _mm256_setr_pd(g[2], g[0], g[1], g[2])};
    constexpr int kZLanes[3] = {0b0100, 0b0010, 0b1001};  // where the z's sit
    int i = begin;
    for (; i + 4 <= end; i += 4) {
        if (!allFree(k.constraint + i, 4)) {
            for (int p = i; p < i + 4; ++p) below |= kickDriftOne(k, p);
            continue;
        }
        const double* m = k.mass + i;
        const __m256d mass[3] = {_mm256_setr_pd(m[0], m[0], m[0], m[1]),
                                 _mm256_setr_pd(m[1], m[1], m[2], m[2]),
                                 _mm256_setr_pd(m[2], m[3], m[3], m[3])};
        for (int lane = 0; lane < 3; ++lane) {
            double* v = k.v + 3 * i + 4 * lane;
            double* x = k.x + 3 * i + 4 * lane;
            const __m256d f = _mm256_loadu_pd(k.force + 3 * i + 4 * lane);
            __m256d vel = _mm256_loadu_pd(v);
            const __m256d acceleration =
                _mm256_sub_pd(_mm256_add_pd(_mm256_div_pd(f, mass[lane]), gravity[lane]),
                              _mm256_mul_pd(damping, vel));
            vel = _mm256_add_pd(vel, _mm256_mul_pd(h, acceleration));
            _mm256_storeu_pd(v, vel);
            const __m256d to = _mm256_add_pd(_mm256_loadu_pd(x), _mm256_mul_pd(dt, vel));
            _mm256_storeu_pd(x, to);
            below |= (_mm256_movemask_pd(_mm256_cmp_pd(to, floor, _CMP_NGE_UQ)) & kZLanes[lane]);
        }
    }
    return i;
}

// Eight free particles are twenty-four doubles, three lanes of eight, the masses and gravity
// spread by permutes.
[[gnu::target("avx2,avx512f")]] int kickDriftAvx512(const KickDrift& k, int begin, int end,
                                                    bool& below) {
    const __m512d h = _mm512_set1_pd(k.h), dt = _mm512_set1_pd(k.dt);
    const __m512d damping = _mm512_set1_pd(k.damping), floor = _mm512_set1_pd(k.floor);
    const __m512d g = _mm512_setr_pd(k.gravity[0], k.gravity[1], k.gravity[2], 0, 0, 0, 0, 0);
    // Component (3 p + a) of lane l: particle p = (8 l + slot) / 3, axis a = (8 l + slot) % 3.
    const __m512i particle[3] = {_mm512_setr_epi64(0, 0, 0, 1, 1, 1, 2, 2),
                                 _mm512_setr_epi64(2, 3, 3, 3, 4, 4, 4, 5),
                                 _mm512_setr_epi64(5, 5, 6, 6, 6, 7, 7, 7)};
    const __m512i axis[3] = {_mm512_setr_epi64(0, 1, 2, 0, 1, 2, 0, 1),
                             _mm512_setr_epi64(2, 0, 1, 2, 0, 1, 2, 0),
                             _mm512_setr_epi64(1, 2, 0, 1, 2, 0, 1, 2)};
    constexpr __mmask8 kZLanes[3] = {0b00100100, 0b01001001, 0b10010010};
    int i = begin;
    for (; i + 8 <= end; i += 8) {
        if (!allFree(k.constraint + i, 8)) {
            for (int p = i; p < i + 8; ++p) below |= kickDriftOne(k, p);
            continue;
        }
        const __m512d masses = _mm512_loadu_pd(k.mass + i);
        for (int lane = 0; lane < 3; ++lane) {
            double* v = k.v + 3 * i + 8 * lane;
            double* x = k.x + 3 * i + 8 * lane;
            const __m512d mass = _mm512_permutexvar_pd(particle[lane], masses);
            const __m512d gravity = _mm512_permutexvar_pd(axis[lane], g);
            const __m512d f = _mm512_loadu_pd(k.force + 3 * i + 8 * lane);
            __m512d vel = _mm512_loadu_pd(v);
            const __m512d acceleration = _mm512_sub_pd(
                _mm512_add_pd(_mm512_div_pd(f, mass), gravity), _mm512_mul_pd(damping, vel));
            vel = _mm512_add_pd(vel, _mm512_mul_pd(h, acceleration));
            _mm512_storeu_pd(v, vel);
            const __m512d to = _mm512_add_pd(_mm512_loadu_pd(x), _mm512_mul_pd(dt, vel));
            _mm512_storeu_pd(x, to);
            below |= _mm512_mask_cmp_pd_mask(kZLanes[lane], to, floor, _CMP_NGE_UQ) != 0;
        }
    }
    return i;
}

#endif

}  // namespace

int simdWidth() {
    static const int width = [] {
        const char* cap = std::getenv("REND_SIMD");
        const std::string_view wanted = cap ? cap : "";
        int lanes = 1;
#if defined(__x86_64__)
        if (__builtin_cpu_supports("avx2")) lanes = 4;
        if (__builtin_cpu_supports("avx512f")) lanes = 8;
#endif
        if (wanted == "scalar") return 1;
        if (wanted == "avx2") return std::min(lanes, 4);
        return lanes;
    }();
    return width;
}

bool kickDrift(const KickDrift& k, int begin, int end) {
    bool below = false;
#if defined(__x86_64__)
    if (simdWidth() == 8)
        begin = kickDriftAvx512(k, begin, end, below);
    else if (simdWidth() == 4)
        begin = kickDriftAvx2(k, begin, end, below);
#endif
    for (int i = begin; i < end; ++i) below |= kickDriftOne(k, i);
    return below;
}

}  // namespace rend::sim
