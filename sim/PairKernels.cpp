#include "sim/PairKernels.h"

#include <immintrin.h>

#include <algorithm>
#include <cmath>

#include "sim/BondLaw.h"

namespace rend::sim {
namespace {

constexpr double kMostCompression = -0.95;  // BondLaw::kMostCompression

/// BondLaw::power for the whole exponents the kernels take (0 to 3).
inline double wholePower(double s, double k) {
    if (k == 0.0) return 1.0;
    if (k == 1.0) return s;
    if (k == 2.0) return s * s;
    return s * s * s;
}

// One loop per stage a scene needs, so each runs without a branch it does not need. The
// expressions are those of the scalar loop (PeridynamicBonds::bondForcesFor, BondLaw)
// term by term: the same bits.
template <BondLawKind kLaw, bool kTheta, bool kBreak, bool kUpdate>
inline double pairLoop(const LinearPairInput& in, const LinearPairOutput& out, int begin, int end) {
    const int* __restrict first = in.first;
    const int* __restrict second = in.second;
    const double* __restrict x = in.x;
    const double* __restrict theta = in.theta;
    double* __restrict force = out.force;
    std::uint8_t* __restrict over = out.over;
    double stiffest = 1.0;
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
        bool past = false;
        if constexpr (kBreak) {  // eqs. 27-28
            double limit = in.limit[u];
            if constexpr (kTheta) limit *= std::max(0.0, 1.0 - in.strengthLoss * thetaBar);
            past = eta > limit;
            over[u] = past;
        }
        if constexpr (kLaw == BondLawKind::PowerLaw) {  // eq. 19, and the tangent in dt
            if (kUpdate && eta < 0.0 && !past && in.alive[in.upper[u]]) {
                const double* v = in.v;
                const double rate =
                    (rx * (v[3 * j] - v[3 * i]) + ry * (v[3 * j + 1] - v[3 * i + 1]) +
                     rz * (v[3 * j + 2] - v[3 * i + 2])) /
                    (length * in.restLength[u]);
                const double s =
                    1.0 + std::max(eta + std::min(0.0, in.dt * rate), kMostCompression);
                const double s2 = s * s;
                double tangent = (2.0 * in.powerC * (1.0 + 3.0 / (s2 * s2)) +
                                  in.powerCStar * in.powerN * (in.powerN - 1.0) *
                                      wholePower(s, in.powerN - 2.0)) /
                                 in.c;
                if constexpr (kTheta) tangent *= std::max(0.0, 1.0 - in.stiffnessLoss * thetaBar);
                stiffest = std::max(stiffest, tangent);
            }
            const double s = 1.0 + std::max(eta, kMostCompression);
            f = 2.0 * in.powerC * (s - 1.0 / (s * s * s)) +
                in.powerCStar * in.powerN * (wholePower(s, in.powerN - 1.0) - 1.0);
        } else if constexpr (kLaw == BondLawKind::Elastoplastic) {  // eq. 20
            const PlasticState state = in.law->yieldStep(eta, in.plastic[in.upper[u]]);
            if (kUpdate && !past && in.alive[in.upper[u]])
                in.plastic[in.upper[u]] = in.plastic[in.twin[u]] = state;
            f = in.law->forceAs<BondLawKind::Elastoplastic>(eta, state);
        } else {
            f = in.c * eta;  // eq. 18
        }
        if constexpr (kTheta) f *= std::max(0.0, 1.0 - in.stiffnessLoss * thetaBar);
        double coef = in.scale[u] * f / length;
        if constexpr (kBreak) coef = past ? 0.0 : coef;
        force[4 * u] = coef * rx;
        force[4 * u + 1] = coef * ry;
        force[4 * u + 2] = coef * rz;
        force[4 * u + 3] = 0.0;
    }
    return stiffest;
}

void gatherLoop(const PairGather& g, int begin, int end) {
    for (int i = begin; i < end; ++i) {
        double sum[3] = {0.0, 0.0, 0.0};
        for (int b = g.offsets[i]; b < g.upperBegin[i]; ++b)
            if (g.alive[b])
                for (int k = 0; k < 3; ++k) sum[k] -= g.pairForce[4 * g.pairOf[b] + k];
        for (int b = g.upperBegin[i], u = g.pairBegin[i]; b < g.offsets[i + 1]; ++b, ++u)
            if (g.alive[b])
                for (int k = 0; k < 3; ++k) sum[k] += g.pairForce[4 * u + k];
        for (int k = 0; k < 3; ++k) g.force[3 * i + k] = sum[k];
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

[[gnu::target("avx2"), gnu::always_inline]] inline __m256d wholePower4(__m256d s, double k) {
    if (k == 0.0) return _mm256_set1_pd(1.0);
    if (k == 1.0) return s;
    if (k == 2.0) return _mm256_mul_pd(s, s);
    return _mm256_mul_pd(_mm256_mul_pd(s, s), s);
}

// Eq. 20 for four pairs: c eta where no lane has yielded (the common case: no exp), else the
// yielded lanes through BondLaw itself. The largest strain is BondLaw::yieldStep's std::max
// (max_pd(eta, m) answers as it does for NaN); the history moves on for the living, unbroken
// bonds, and is written only where it grew (both copies always hold the same value).
template <bool kUpdate>
[[gnu::target("avx2")]] __m256d plasticForces(const LinearPairInput& in, int u, __m256d eta,
                                              __m256d past) {
    const int* upper = in.upper + u;
    const PlasticState* plastic = in.plastic;
    const __m256d held = _mm256_setr_pd(plastic[upper[0]].maxStrain, plastic[upper[1]].maxStrain,
                                        plastic[upper[2]].maxStrain, plastic[upper[3]].maxStrain);
    const __m256d largest4 = _mm256_max_pd(eta, held);
    if constexpr (kUpdate) {
        const int grew = _mm256_movemask_pd(_mm256_cmp_pd(largest4, held, _CMP_NEQ_UQ)) &
                         ~_mm256_movemask_pd(past);
        if (grew) {
            double largest[4];
            _mm256_storeu_pd(largest, largest4);
            for (int k = 0; k < 4; ++k)
                if (((grew >> k) & 1) && in.alive[upper[k]])
                    in.plastic[upper[k]].maxStrain = in.plastic[in.twin[u + k]].maxStrain =
                        largest[k];
        }
    }
    const __m256d yielded =
        _mm256_cmp_pd(largest4, _mm256_set1_pd(in.law->yieldStrain), _CMP_GT_OQ);
    if (_mm256_movemask_pd(yielded) == 0) return _mm256_mul_pd(_mm256_set1_pd(in.c), eta);
    double strain[4], largest[4], f[4];
    _mm256_storeu_pd(strain, eta);
    _mm256_storeu_pd(largest, largest4);
    for (int k = 0; k < 4; ++k)
        f[k] = in.law->forceAs<BondLawKind::Elastoplastic>(strain[k], PlasticState{largest[k]});
    return _mm256_loadu_pd(f);
}

// Four pairs at a time: the same operations in the same order, four lanes wide. The maxima and
// minima take their arguments in the order that gives std::max and std::min's answer for NaN.
template <BondLawKind kLaw, bool kTheta, bool kBreak, bool kUpdate>
[[gnu::target("avx2")]] int pairLoopAvx2(const LinearPairInput& in, const LinearPairOutput& out,
                                         int begin, int end, double& stiffest) {
    const __m256d one = _mm256_set1_pd(1.0), zero = _mm256_setzero_pd();
    const __m256d half = _mm256_set1_pd(0.5), c = _mm256_set1_pd(in.c);
    const __m256d expansion = _mm256_set1_pd(in.expansion);
    const __m256d stiffnessLoss = _mm256_set1_pd(in.stiffnessLoss);
    const __m256d strengthLoss = _mm256_set1_pd(in.strengthLoss);
    const __m256d most = _mm256_set1_pd(kMostCompression), dt = _mm256_set1_pd(in.dt);
    const __m256d twoC = _mm256_set1_pd(2.0 * in.powerC);
    const __m256d starN = _mm256_set1_pd(in.powerCStar * in.powerN);
    const __m256d starNN = _mm256_set1_pd(in.powerCStar * in.powerN * (in.powerN - 1.0));
    const __m256d three = _mm256_set1_pd(3.0);
    __m256d stiffest4 = one;
    int u = begin;
    for (; u + 4 <= end; u += 4) {
        const Lanes xi = loadPositions(in.x, in.first + u);
        const Lanes xj = loadPositions(in.x, in.second + u);
        const __m256d rx = _mm256_sub_pd(xj.x, xi.x), ry = _mm256_sub_pd(xj.y, xi.y);
        const __m256d rz = _mm256_sub_pd(xj.z, xi.z);
        const __m256d squared = _mm256_add_pd(
            _mm256_add_pd(_mm256_mul_pd(rx, rx), _mm256_mul_pd(ry, ry)), _mm256_mul_pd(rz, rz));
        const __m256d length = _mm256_sqrt_pd(squared);
        const __m256d rest = _mm256_loadu_pd(in.restLength + u);
        __m256d eta = _mm256_sub_pd(_mm256_div_pd(length, rest), one);
        __m256d thetaBar = zero, stiffness = one;
        if constexpr (kTheta) {
            const int *a = in.first + u, *b = in.second + u;  // loads: AMD's gathers cost more
            const double* t = in.theta;
            thetaBar = _mm256_mul_pd(
                half, _mm256_add_pd(_mm256_set_pd(t[a[3]], t[a[2]], t[a[1]], t[a[0]]),
                                    _mm256_set_pd(t[b[3]], t[b[2]], t[b[1]], t[b[0]])));
            eta = _mm256_sub_pd(eta, _mm256_mul_pd(expansion, thetaBar));
            stiffness = _mm256_max_pd(_mm256_sub_pd(one, _mm256_mul_pd(stiffnessLoss, thetaBar)),
                                      zero);  // max(0, 1 - loss theta)
        }
        __m256d past = zero;
        if constexpr (kBreak) {
            __m256d limit = _mm256_loadu_pd(in.limit + u);
            if constexpr (kTheta)
                limit = _mm256_mul_pd(
                    limit,
                    _mm256_max_pd(_mm256_sub_pd(one, _mm256_mul_pd(strengthLoss, thetaBar)), zero));
            past = _mm256_cmp_pd(eta, limit, _CMP_GT_OQ);
            const int bits = _mm256_movemask_pd(past);
            for (int k = 0; k < 4; ++k) out.over[u + k] = (bits >> k) & 1;
        }
        __m256d f;
        if constexpr (kLaw == BondLawKind::PowerLaw) {
            if constexpr (kUpdate) {
                const Lanes vi = loadPositions(in.v, in.first + u);
                const Lanes vj = loadPositions(in.v, in.second + u);
                const __m256d dot =
                    _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(rx, _mm256_sub_pd(vj.x, vi.x)),
                                                _mm256_mul_pd(ry, _mm256_sub_pd(vj.y, vi.y))),
                                  _mm256_mul_pd(rz, _mm256_sub_pd(vj.z, vi.z)));
                const __m256d rate = _mm256_div_pd(dot, _mm256_mul_pd(length, rest));
                const __m256d ahead = _mm256_max_pd(
                    most, _mm256_add_pd(eta, _mm256_min_pd(_mm256_mul_pd(dt, rate), zero)));
                const __m256d s = _mm256_add_pd(one, ahead), s2 = _mm256_mul_pd(s, s);
                __m256d tangent = _mm256_div_pd(
                    _mm256_add_pd(
                        _mm256_mul_pd(
                            twoC, _mm256_add_pd(one, _mm256_div_pd(three, _mm256_mul_pd(s2, s2)))),
                        _mm256_mul_pd(starNN, wholePower4(s, in.powerN - 2.0))),
                    c);
                if constexpr (kTheta) tangent = _mm256_mul_pd(tangent, stiffness);
                const int* upper = in.upper + u;
                const __m256d alive = _mm256_set_pd(in.alive[upper[3]], in.alive[upper[2]],
                                                    in.alive[upper[1]], in.alive[upper[0]]);
                const __m256d counts =
                    _mm256_and_pd(_mm256_andnot_pd(past, _mm256_cmp_pd(eta, zero, _CMP_LT_OQ)),
                                  _mm256_cmp_pd(alive, zero, _CMP_NEQ_OQ));
                stiffest4 = _mm256_max_pd(_mm256_blendv_pd(one, tangent, counts), stiffest4);
            }
            const __m256d s = _mm256_add_pd(one, _mm256_max_pd(most, eta));
            f = _mm256_add_pd(
                _mm256_mul_pd(
                    twoC,
                    _mm256_sub_pd(s, _mm256_div_pd(one, _mm256_mul_pd(_mm256_mul_pd(s, s), s)))),
                _mm256_mul_pd(starN, _mm256_sub_pd(wholePower4(s, in.powerN - 1.0), one)));
        } else if constexpr (kLaw == BondLawKind::Elastoplastic) {
            f = plasticForces<kUpdate>(in, u, eta, past);
        } else {
            f = _mm256_mul_pd(c, eta);
        }
        if constexpr (kTheta) f = _mm256_mul_pd(f, stiffness);
        __m256d coef = _mm256_div_pd(_mm256_mul_pd(_mm256_loadu_pd(in.scale + u), f), length);
        if constexpr (kBreak) coef = _mm256_blendv_pd(coef, zero, past);
        // Four x y z 0 slots from the three lanes of x, of y and of z.
        const __m256d fx = _mm256_mul_pd(coef, rx), fy = _mm256_mul_pd(coef, ry);
        const __m256d fz = _mm256_mul_pd(coef, rz);
        const __m256d xy02 = _mm256_unpacklo_pd(fx, fy), xy13 = _mm256_unpackhi_pd(fx, fy);
        const __m256d z02 = _mm256_unpacklo_pd(fz, zero), z13 = _mm256_unpackhi_pd(fz, zero);
        double* slot = out.force + 4 * std::size_t(u);
        _mm256_storeu_pd(slot, _mm256_permute2f128_pd(xy02, z02, 0x20));
        _mm256_storeu_pd(slot + 4, _mm256_permute2f128_pd(xy13, z13, 0x20));
        _mm256_storeu_pd(slot + 8, _mm256_permute2f128_pd(xy02, z02, 0x31));
        _mm256_storeu_pd(slot + 12, _mm256_permute2f128_pd(xy13, z13, 0x31));
    }
    double lanes[4];
    _mm256_storeu_pd(lanes, stiffest4);
    for (const double t : lanes) stiffest = std::max(stiffest, t);
    return u;
}

// A pair force is one four-lane load; the lanes add as the scalar sums do.
[[gnu::target("avx2")]] void gatherAvx2(const PairGather& g, int begin, int end) {
    const int* __restrict offsets = g.offsets;
    const int* __restrict upperBegin = g.upperBegin;
    const int* __restrict pairBegin = g.pairBegin;
    const int* __restrict pairOf = g.pairOf;
    const std::uint8_t* __restrict alive = g.alive;
    const double* __restrict pairForce = g.pairForce;
    double* __restrict force = g.force;
    for (int i = begin; i < end; ++i) {
        __m256d sum = _mm256_setzero_pd();
        for (int b = offsets[i]; b < upperBegin[i]; ++b)
            if (alive[b]) sum = _mm256_sub_pd(sum, _mm256_loadu_pd(pairForce + 4 * pairOf[b]));
        for (int b = upperBegin[i], u = pairBegin[i]; b < offsets[i + 1]; ++b, ++u)
            if (alive[b]) sum = _mm256_add_pd(sum, _mm256_loadu_pd(pairForce + 4 * u));
        double lanes[4];
        _mm256_storeu_pd(lanes, sum);
        force[3 * i] = lanes[0], force[3 * i + 1] = lanes[1], force[3 * i + 2] = lanes[2];
    }
}

bool hasAvx2() {
    static const bool has = __builtin_cpu_supports("avx2");
    return has;
}
#endif

template <BondLawKind kLaw, bool kTheta, bool kBreak, bool kUpdate>
double pairs(const LinearPairInput& in, const LinearPairOutput& out, int begin, int end) {
    double stiffest = 1.0;
#if defined(__x86_64__)
    if (hasAvx2())
        begin = pairLoopAvx2<kLaw, kTheta, kBreak, kUpdate>(in, out, begin, end, stiffest);
#endif
    return std::max(stiffest, pairLoop<kLaw, kTheta, kBreak, kUpdate>(in, out, begin, end));
}

template <BondLawKind kLaw, bool kUpdate>
double pairsFor(const LinearPairInput& in, const LinearPairOutput& out, int begin, int end) {
    const bool theta = in.theta != nullptr, breakable = in.limit != nullptr;
    if (theta && breakable) return pairs<kLaw, true, true, kUpdate>(in, out, begin, end);
    if (theta) return pairs<kLaw, true, false, kUpdate>(in, out, begin, end);
    if (breakable) return pairs<kLaw, false, true, kUpdate>(in, out, begin, end);
    return pairs<kLaw, false, false, kUpdate>(in, out, begin, end);
}

}  // namespace

double linearPairForces(const LinearPairInput& in, const LinearPairOutput& out, int begin,
                        int end) {
    switch (in.law->kind) {
        case BondLawKind::Linear:
            return pairsFor<BondLawKind::Linear, false>(in, out, begin, end);
        case BondLawKind::PowerLaw:
            return in.update ? pairsFor<BondLawKind::PowerLaw, true>(in, out, begin, end)
                             : pairsFor<BondLawKind::PowerLaw, false>(in, out, begin, end);
        case BondLawKind::Elastoplastic:
            return in.update ? pairsFor<BondLawKind::Elastoplastic, true>(in, out, begin, end)
                             : pairsFor<BondLawKind::Elastoplastic, false>(in, out, begin, end);
    }
    return 1.0;
}

void gatherPairForces(const PairGather& g, int begin, int end) {
#if defined(__x86_64__)
    if (hasAvx2()) return gatherAvx2(g, begin, end);
#endif
    gatherLoop(g, begin, end);
}

}  // namespace rend::sim
