#include "sim/PairKernels.h"

#include <immintrin.h>

#include <algorithm>
#include <cmath>

namespace rend::sim {
namespace {

// One loop per stage a scene needs, so each vectorises without a branch inside. The expressions
// are those of the scalar loop (PeridynamicBonds::bondForcesFor) term by term: the same bits.
template <bool kTheta, bool kBreak>
inline void pairLoop(const LinearPairInput& in, const LinearPairOutput& out, int begin, int end) {
    const int* __restrict first = in.first;
    const int* __restrict second = in.second;
    const double* __restrict x = in.x;
    const double* __restrict theta = in.theta;
    double* __restrict fx = out.fx;
    double* __restrict fy = out.fy;
    double* __restrict fz = out.fz;
    std::uint8_t* __restrict over = out.over;
    for (int u = begin; u < end; ++u) {
        const int i = first[u], j = second[u];
        const double rx = x[3 * j] - x[3 * i];
        const double ry = x[3 * j + 1] - x[3 * i + 1];
        const double rz = x[3 * j + 2] - x[3 * i + 2];
        const double length = std::sqrt(rx * rx + ry * ry + rz * rz);
        double eta = length / in.restLength[u] - 1.0;  // eq. 10
        double thetaBar = 0.0, f;
        if constexpr (kTheta) {
            thetaBar = 0.5 * (theta[i] + theta[j]);
            eta -= in.expansion * thetaBar;
        }
        f = in.c * eta;  // eq. 18
        if constexpr (kTheta) f *= std::max(0.0, 1.0 - in.stiffnessLoss * thetaBar);
        double coef = in.scale[u] * f / length;
        if constexpr (kBreak) {  // eqs. 27-28
            double limit = in.limit[u];
            if constexpr (kTheta) limit *= std::max(0.0, 1.0 - in.strengthLoss * thetaBar);
            const bool past = eta > limit;
            over[u] = past;
            coef = past ? 0.0 : coef;
        }
        fx[u] = coef * rx;
        fy[u] = coef * ry;
        fz[u] = coef * rz;
    }
}

#if defined(__x86_64__)
// The x, y and z of four particles as three four-lane vectors, from plain loads: AMD's gathers
// cost more than the loads and shuffles.
struct Lanes {
    __m256d x, y, z;
};
[[gnu::target("avx2"), gnu::always_inline]] inline Lanes loadPositions(const double* p,
                                                                       const int* index) {
    const double* a = p + 3 * index[0];
    const double* b = p + 3 * index[1];
    const double* c = p + 3 * index[2];
    const double* d = p + 3 * index[3];
    const __m256d ac = _mm256_set_m128d(_mm_loadu_pd(c), _mm_loadu_pd(a));
    const __m256d bd = _mm256_set_m128d(_mm_loadu_pd(d), _mm_loadu_pd(b));
    return {_mm256_unpacklo_pd(ac, bd), _mm256_unpackhi_pd(ac, bd),
            _mm256_set_pd(d[2], c[2], b[2], a[2])};
}

// Four pairs at a time: the same operations in the same order, four lanes wide.
template <bool kTheta, bool kBreak>
[[gnu::target("avx2")]] int pairLoopAvx2(const LinearPairInput& in, const LinearPairOutput& out,
                                         int begin, int end) {
    const __m256d one = _mm256_set1_pd(1.0), zero = _mm256_setzero_pd();
    const __m256d half = _mm256_set1_pd(0.5), c = _mm256_set1_pd(in.c);
    const __m256d expansion = _mm256_set1_pd(in.expansion);
    const __m256d stiffnessLoss = _mm256_set1_pd(in.stiffnessLoss);
    const __m256d strengthLoss = _mm256_set1_pd(in.strengthLoss);
    int u = begin;
    for (; u + 4 <= end; u += 4) {
        const __m128i i = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in.first + u));
        const __m128i j = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in.second + u));
        const Lanes xi = loadPositions(in.x, in.first + u);
        const Lanes xj = loadPositions(in.x, in.second + u);
        const __m256d rx = _mm256_sub_pd(xj.x, xi.x), ry = _mm256_sub_pd(xj.y, xi.y);
        const __m256d rz = _mm256_sub_pd(xj.z, xi.z);
        const __m256d squared = _mm256_add_pd(
            _mm256_add_pd(_mm256_mul_pd(rx, rx), _mm256_mul_pd(ry, ry)), _mm256_mul_pd(rz, rz));
        const __m256d length = _mm256_sqrt_pd(squared);
        __m256d eta = _mm256_sub_pd(_mm256_div_pd(length, _mm256_loadu_pd(in.restLength + u)), one);
        __m256d thetaBar = zero;
        if constexpr (kTheta) {
            thetaBar = _mm256_mul_pd(half, _mm256_add_pd(_mm256_i32gather_pd(in.theta, i, 8),
                                                         _mm256_i32gather_pd(in.theta, j, 8)));
            eta = _mm256_sub_pd(eta, _mm256_mul_pd(expansion, thetaBar));
        }
        __m256d f = _mm256_mul_pd(c, eta);
        if constexpr (kTheta)  // times max(0, 1 - loss theta)
            f = _mm256_mul_pd(
                f, _mm256_max_pd(_mm256_sub_pd(one, _mm256_mul_pd(stiffnessLoss, thetaBar)), zero));
        __m256d coef = _mm256_div_pd(_mm256_mul_pd(_mm256_loadu_pd(in.scale + u), f), length);
        if constexpr (kBreak) {
            __m256d limit = _mm256_loadu_pd(in.limit + u);
            if constexpr (kTheta)
                limit = _mm256_mul_pd(
                    limit,
                    _mm256_max_pd(_mm256_sub_pd(one, _mm256_mul_pd(strengthLoss, thetaBar)), zero));
            const __m256d past = _mm256_cmp_pd(eta, limit, _CMP_GT_OQ);
            const int bits = _mm256_movemask_pd(past);
            for (int k = 0; k < 4; ++k) out.over[u + k] = (bits >> k) & 1;
            coef = _mm256_blendv_pd(coef, zero, past);
        }
        _mm256_storeu_pd(out.fx + u, _mm256_mul_pd(coef, rx));
        _mm256_storeu_pd(out.fy + u, _mm256_mul_pd(coef, ry));
        _mm256_storeu_pd(out.fz + u, _mm256_mul_pd(coef, rz));
    }
    return u;
}

bool hasAvx2() {
    static const bool has = __builtin_cpu_supports("avx2");
    return has;
}
#endif

template <bool kTheta, bool kBreak>
void pairs(const LinearPairInput& in, const LinearPairOutput& out, int begin, int end) {
#if defined(__x86_64__)
    if (hasAvx2()) begin = pairLoopAvx2<kTheta, kBreak>(in, out, begin, end);
#endif
    pairLoop<kTheta, kBreak>(in, out, begin, end);  // the rest
}

}  // namespace

void linearPairForces(const LinearPairInput& in, const LinearPairOutput& out, int begin, int end) {
    const bool theta = in.theta != nullptr, breakable = in.limit != nullptr;
    if (theta && breakable) return pairs<true, true>(in, out, begin, end);
    if (theta) return pairs<true, false>(in, out, begin, end);
    if (breakable) return pairs<false, true>(in, out, begin, end);
    pairs<false, false>(in, out, begin, end);
}

}  // namespace rend::sim
