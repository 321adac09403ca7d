#include "sim/StepKernels.h"

#include <immintrin.h>

namespace rend::sim {
namespace {

constexpr std::int16_t kFree = -1;

inline void kickDriftOne(const KickDrift& k, int i) {
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
}

#if defined(__x86_64__)
// Four free particles are twelve doubles, three lanes of four: x0 y0 z0 x1 | y1 z1 x2 y2 |
// z2 x3 y3 z3, with the masses and gravity spread to match.
[[gnu::target("avx2")]] int kickDriftAvx2(const KickDrift& k, int begin, int end) {
    const __m256d h = _mm256_set1_pd(k.h), dt = _mm256_set1_pd(k.dt);
    const __m256d damping = _mm256_set1_pd(k.damping);
    const double* g = k.gravity;
    const __m256d gravity[3] = {_mm256_setr_pd(g[0], g[1], g[2], g[0]),
                                _mm256_setr_pd(g[1], g[2], g[0], g[1]),
                                _mm256_setr_pd(g[2], g[0], g[1], g[2])};
    int i = begin;
    for (; i + 4 <= end; i += 4) {
        std::uint64_t tags;
        __builtin_memcpy(&tags, k.constraint + i, sizeof tags);
        if (tags != 0xffffffffffffffffull) {  // not four free particles (kFree is all ones)
            for (int p = i; p < i + 4; ++p) kickDriftOne(k, p);
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
            _mm256_storeu_pd(x, _mm256_add_pd(_mm256_loadu_pd(x), _mm256_mul_pd(dt, vel)));
        }
    }
    return i;
}

bool hasAvx2() {
    static const bool has = __builtin_cpu_supports("avx2");
    return has;
}
#endif

}  // namespace

void kickDrift(const KickDrift& k, int begin, int end) {
#if defined(__x86_64__)
    if (hasAvx2()) begin = kickDriftAvx2(k, begin, end);
#endif
    for (int i = begin; i < end; ++i) kickDriftOne(k, i);
}

}  // namespace rend::sim
