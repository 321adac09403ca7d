#include "sim/PairKernels.h"

#include <immintrin.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include "sim/BondLaw.h"
#include "sim/LawExp.h"
#include "sim/SimdRuns.h"
#include "sim/StepKernels.h"

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

inline double nearestReach(const LinearPairInput& in);

// One loop per stage a scene needs, so each runs without a branch it does not need. The
// expressions are those of the scalar loop (PeridynamicBonds::bondForcesFor, BondLaw)
// term by term: the same bits.
template <BondLawKind kLaw, bool kTheta, bool kBreak, bool kUpdate>
inline double pairLoop(const LinearPairInput& in, const LinearPairOutput& out, int begin, int end) {
    const int* __restrict first = in.first;
    const int* __restrict second = in.second;
    const double* __restrict x = in.x;
    const double* __restrict theta = in.theta;
    std::uint8_t* __restrict over = out.over;
    double stiffest = 1.0;
    // LinearPairOutput::nearest, from the kernels' reach (the look-ahead here needs none).
    constexpr bool kNearest = kLaw == BondLawKind::PowerLaw && kUpdate;
    const double reach = kNearest && out.nearest ? nearestReach(in) : 0.0;
    double nearest = std::numeric_limits<double>::infinity();
    for (int u = begin; u < end; ++u) {
        const int i = first[u], j = second[u];
        const double rx = x[3 * j] - x[3 * i];
        const double ry = x[3 * j + 1] - x[3 * i + 1];
        const double rz = x[3 * j + 2] - x[3 * i + 2];
        const double length = std::sqrt(rx * rx + ry * ry + rz * rz);
        // Eq. 10; the linear and power laws' times rest (sim/PairKernelSimd.inc's kByRest).
        constexpr bool kByRest = kLaw == BondLawKind::Linear || kLaw == BondLawKind::PowerLaw;
        const double rest = in.restLength[u];
        double eta = kByRest ? length - rest : length / rest - 1.0;
        double thetaBar = 0.0, f, cube = 1.0;
        if constexpr (kTheta) {
            thetaBar = 0.5 * (theta[i] + theta[j]);
            const double swelling = in.expansion * thetaBar;
            eta -= kByRest ? rest * swelling : swelling;
        }
        bool past = false;
        if constexpr (kBreak) {  // eqs. 27-28
            double limit = in.limit[u];
            if constexpr (kTheta) limit *= std::max(0.0, 1.0 - in.strengthLoss * thetaBar);
            if constexpr (kByRest) limit = rest * limit;
            past = eta > limit;
            const unsigned bit = unsigned(u) % kPairTile;
            std::uint8_t& row = over[u / kPairTile];
            row = std::uint8_t((bit == 0 ? 0u : row & ~(1u << bit)) | unsigned(past) << bit);
            if (out.approaching) {  // every pair: flaggedApproachRate's exact test decides
                std::uint8_t& near = out.approaching[u / kPairTile];
                near = std::uint8_t((bit == 0 ? 0u : near) | 1u << bit);
            }
        }
        if constexpr (kNearest) nearest = std::min(nearest, eta - reach * rest);
        if constexpr (kLaw == BondLawKind::PowerLaw) {  // eq. 19, and the tangent in dt
            if (kUpdate && eta < 0.0 && !past && i >= in.ownBegin && in.alive[in.upper[u]]) {
                const double* v = in.v;
                const double rate =
                    (rx * (v[3 * j] - v[3 * i]) + ry * (v[3 * j + 1] - v[3 * i + 1]) +
                     rz * (v[3 * j + 2] - v[3 * i + 2])) /
                    (length * in.restLength[u]);
                const double strain = eta / rest;
                const double s =
                    1.0 + std::max(strain + std::min(0.0, in.dt * rate), kMostCompression);
                const double s2 = s * s;
                double tangent = (2.0 * in.powerC * (1.0 + 3.0 / (s2 * s2)) +
                                  in.powerCStar * in.powerN * (in.powerN - 1.0) *
                                      wholePower(s, in.powerN - 2.0)) /
                                 in.c;
                if constexpr (kTheta) tangent *= std::max(0.0, 1.0 - in.stiffnessLoss * thetaBar);
                stiffest = std::max(stiffest, tangent);
            }
            const BondLaw::PowerLawByRest parts = in.law->powerLawByRest(eta, rest);
            f = parts.numerator, cube = parts.denominator;          // divided by below
        } else if constexpr (kLaw == BondLawKind::Elastoplastic) {  // eq. 20
            const PlasticState state = in.law->yieldStep(eta, PlasticState{in.held[u]});
            if (kUpdate && !past && in.alive[in.upper[u]]) in.held[u] = state.maxStrain;
            f = in.law->forceAs<BondLawKind::Elastoplastic>(eta, state);
        } else {
            f = in.c * eta;  // eq. 18
        }
        if constexpr (kTheta) f *= std::max(0.0, 1.0 - in.stiffnessLoss * thetaBar);
        double coef = in.scale[u] * f /
                      (kLaw == BondLawKind::Linear     ? rest * length
                       : kLaw == BondLawKind::PowerLaw ? cube * length
                                                       : length);
        if constexpr (kBreak) coef = past ? 0.0 : coef;
        double* slot = out.slot(u);
        const int stride = out.slotStep();
        slot[0] = coef * rx, slot[stride] = coef * ry, slot[2 * stride] = coef * rz;
        if (!out.rows) slot[3] = 0.0;
    }
    if (kNearest && out.nearest) *out.nearest = std::min(*out.nearest, nearest);
    return stiffest;
}

/// One pair's term of Membrane::failureApproachRate (its expressions, in its order), or 0 where
/// it does not count.
inline double approachOf(const LinearPairInput& in, const ApproachRate& a, int u) {
    const int i = in.first[u], j = in.second[u];
    if (a.pad[u] || i < a.ownBegin || i >= a.ownEnd || !in.alive[in.upper[u]]) return 0.0;
    const double* x = in.x;
    const double* v = in.v;
    const double rx = x[3 * j] - x[3 * i], ry = x[3 * j + 1] - x[3 * i + 1];
    const double rz = x[3 * j + 2] - x[3 * i + 2];
    const double rest = in.restLength[u];
    const double thetaBar = in.theta ? 0.5 * (in.theta[i] + in.theta[j]) : 0.0;
    const double critical = a.critical * std::max(0.0, 1.0 - a.strengthLoss * thetaBar);
    const double unstretched = 1.0 + a.expansion * thetaBar;
    const double loaded = rest * (unstretched + 0.5 * critical);
    const double squared = rx * rx + ry * ry + rz * rz;
    if (!(critical > 0.0 && squared > loaded * loaded)) return 0.0;
    const double length = std::sqrt(squared);
    const double rate = (rx * (v[3 * j] - v[3 * i]) + ry * (v[3 * j + 1] - v[3 * i + 1]) +
                         rz * (v[3 * j + 2] - v[3 * i + 2])) /
                        (length * rest);
    if (!(rate > 0.0)) return 0.0;
    const double margin = critical - (length / rest - unstretched);
    const double value = rate / std::max(0.5 * margin, a.delta * critical);
    return value > 0.0 ? value : 0.0;  // std::max(fastest, value) keeps fastest for NaN
}

/// The look-ahead strain (1 + it is eq. 19's s) at or above which a compressed pair cannot raise
/// the largest tangent so far, `stiffest` (over c with theta, else its numerator; the kernels'
/// stiffestSoFar); infinity where every compressed pair may. For 0 < s < 1 the numerator is at most
/// 2C (1 + 3 / s^4) + max(C* n (n - 1), 0) (s^(n-2) <= 1 for the whole exponents n - 2 >= 0
/// wholePower() takes), falling in s: below the s where that bound equals `stiffest`, with a
/// margin far above the rounding of either side. With theta the tangent is the numerator over c
/// times a stiffness of at most 1.
inline double lookAheadReach(const LinearPairInput& in, double stiffest, bool theta) {
    constexpr double kEverywhere = std::numeric_limits<double>::infinity();
    const double starNN = std::max(in.powerCStar * in.powerN * (in.powerN - 1.0), 0.0);
    if (!(in.powerC > 0.0) || !(starNN <= 1e4 * in.powerC) || in.powerN < 2.0) return kEverywhere;
    const double numerator = theta ? stiffest * in.c : stiffest;
    const double t = (numerator - starNN) / (2.0 * in.powerC) - 1.0;  // 3 / s^4 where equal
    if (!(t > 0.0)) return kEverywhere;
    return std::sqrt(std::sqrt(3.0 / t)) - 1.0 + 1e-7;
}

/// The reach the kernels start from (pairLoopSimd's), for LinearPairOutput::nearest.
inline double nearestReach(const LinearPairInput& in) {
    return in.theta ? lookAheadReach(in, in.stiffestKnown, true)
                    : lookAheadReach(in, in.stiffestKnown * in.c * (1.0 - 0x1p-50), false);
}

#if defined(__x86_64__)
// Each width's code is compiled for its instruction set: GCC by `#pragma GCC target`, clang (the
// fuzz build) by `#pragma clang attribute`.
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2,fma"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2,fma")
#endif
namespace avx2 {

using V = __m256d;
using M = __m256d;
constexpr int kLanes = 4;
constexpr int kRootRows = 0;  // PairKernelSimd.inc: each row's root in its pass

// Four lanes; a mask is all ones or all zeros per lane.
struct Simd {
    static V set1(double a) { return _mm256_set1_pd(a); }
    static V zero() { return _mm256_setzero_pd(); }
    static V load(const double* p) { return _mm256_loadu_pd(p); }
    static void store(double* p, V a) { _mm256_storeu_pd(p, a); }
    static V add(V a, V b) { return _mm256_add_pd(a, b); }
    static V sub(V a, V b) { return _mm256_sub_pd(a, b); }
    static V mul(V a, V b) { return _mm256_mul_pd(a, b); }
    static V fma(V a, V b, V c) { return _mm256_fmadd_pd(a, b, c); }  ///< a b + c, one rounding
    static V div(V a, V b) { return _mm256_div_pd(a, b); }
    static V sqrt(V a) { return _mm256_sqrt_pd(a); }
    static V max(V a, V b) { return _mm256_max_pd(a, b); }
    static V min(V a, V b) { return _mm256_min_pd(a, b); }
    static M gt(V a, V b) { return _mm256_cmp_pd(a, b, _CMP_GT_OQ); }
    static M ge(V a, V b) { return _mm256_cmp_pd(a, b, _CMP_GE_OQ); }
    /// p 2^n1 2^n2 for the n of t = x log2e + lawexp::kShift (sim/LawExp.cpp).
    static V scaleByPow2(V p, V t) {
        const __m256i whole =
            _mm256_sub_epi64(_mm256_castpd_si256(t), _mm256_set1_epi64x(lawexp::kShiftBits));
        const __m256i n1 = _mm256_sub_epi64(
            _mm256_srli_epi64(_mm256_add_epi64(whole, _mm256_set1_epi64x(2048)), 1),
            _mm256_set1_epi64x(1024));
        const __m256i n2 = _mm256_sub_epi64(whole, n1), bias = _mm256_set1_epi64x(1023);
        const V s1 = _mm256_castsi256_pd(_mm256_slli_epi64(_mm256_add_epi64(n1, bias), 52));
        const V s2 = _mm256_castsi256_pd(_mm256_slli_epi64(_mm256_add_epi64(n2, bias), 52));
        return mul(mul(p, s1), s2);
    }
    static M lt(V a, V b) { return _mm256_cmp_pd(a, b, _CMP_LT_OQ); }
    static M neqOrdered(V a, V b) { return _mm256_cmp_pd(a, b, _CMP_NEQ_OQ); }
    static M neqUnordered(V a, V b) { return _mm256_cmp_pd(a, b, _CMP_NEQ_UQ); }
    static M noLanes() { return _mm256_setzero_pd(); }
    static M andNot(M a, M b) { return _mm256_andnot_pd(a, b); }  ///< not a, and b
    static M both(M a, M b) { return _mm256_and_pd(a, b); }
    static M either(M a, M b) { return _mm256_or_pd(a, b); }
    static V blend(V a, V b, M m) { return _mm256_blendv_pd(a, b, m); }  ///< m ? b : a
    static unsigned bits(M m) { return unsigned(_mm256_movemask_pd(m)); }
    static M maskOf(unsigned bits) {
        const __m256i lane = _mm256_setr_epi64x(1, 2, 4, 8);
        return _mm256_castsi256_pd(
            _mm256_cmpeq_epi64(_mm256_and_si256(_mm256_set1_epi64x(bits), lane), lane));
    }
    template <class Read>
    [[gnu::always_inline]] static V lanes(Read read) {
        return _mm256_setr_pd(read(0), read(1), read(2), read(3));
    }
    /// base[index[k]] for four lanes: one hardware gather.
    [[gnu::always_inline]] static V gather(const double* base, const int* index) {
        return _mm256_i32gather_pd(base, _mm_loadu_si128(reinterpret_cast<const __m128i*>(index)),
                                   8);
    }
    /// Four 16-bit counts from p as doubles.
    [[gnu::always_inline]] static V countsAsDoubles(const std::uint16_t* p) {
        return _mm256_cvtepi32_pd(
            _mm_cvtepu16_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))));
    }
    /// The x, y and z of four consecutive particles from p (the first's x): three loads.
    [[gnu::always_inline]] static void loadRun(const double* p, V& x, V& y, V& z) {
        loadRun4(p, x, y, z);
    }
    /// The x, y and z of four particles from plain loads: AMD's gathers cost more.
    [[gnu::always_inline]] static void loadPositions(const double* p, const int* index, V& x, V& y,
                                                     V& z) {
        const double* a = p + 3 * index[0];
        const double* b = p + 3 * index[1];
        const double* c = p + 3 * index[2];
        const double* d = p + 3 * index[3];
        const V ac = _mm256_set_m128d(_mm_loadu_pd(c), _mm_loadu_pd(a));
        const V bd = _mm256_set_m128d(_mm_loadu_pd(d), _mm_loadu_pd(b));
        x = _mm256_unpacklo_pd(ac, bd), y = _mm256_unpackhi_pd(ac, bd);
        z = _mm256_setr_pd(a[2], b[2], c[2], d[2]);
    }
    /// The lanes' x, y and z in their row's slots (half a row: the slots are in rows).
    [[gnu::always_inline]] static void storeSlots(double* slot, V fx, V fy, V fz, int stride) {
        _mm256_storeu_pd(slot, fx);
        _mm256_storeu_pd(slot + stride, fy);
        _mm256_storeu_pd(slot + 2 * stride, fz);
    }
};

#include "sim/PairKernelSimd.inc"

}  // namespace avx2

// Eight lanes as two AVX2 vectors, each operation on both halves: the pair kernel at width 4
// takes a tile's row (kPairTile pairs) in one pass, its two square roots and divisions side by
// side, and its per-row work (the ends, the class, the flags' byte) once. Four lanes a pass, each
// root and division waited on the one before it (cpu-clock samples on the instructions after
// them: a third of the kernel's); eight, on one Zen 3 core, crack_path_sources at 10^4, linear
// law, alternate runs: 27.9 -> 24.7, 28.7 -> 25.0, 28.0 -> 25.1 ns per particle-step; stretch
// 20.7 -> 17.8, 20.8 -> 17.6.
namespace avx2x2 {

struct V {
    __m256d lo, hi;
};
using M = V;
using Half = avx2::Simd;
constexpr int kLanes = 8;
// The rows' roots sixteen at a time (PairKernelSimd.inc's kRootRows), then their forces: the
// roots were the kernel's longest wait (a fifth of its cpu-clock samples on the instruction after
// them), each row's root and division behind the row before's, with its ~200 instructions
// filling the core's window. Apart, sixteen roots (a 5 KiB buffer) issue back to back. On one
// Zen 3 core, crack_path_sources at 10^4, fastest of ten alternate runs, ns per particle-step:
// linear 23.0 -> 21.2 (8 rows 21.5, 32 rows 21.2), power law 27.4 -> 25.8, elastoplastic 27.0 ->
// 25.4, stretch 16.6 -> 15.6; one row ahead in the same loop instead: 22.1. On the AVX-512 Zen 5
// the same split was slower (README, issue 16), so the avx512 loop keeps one pass.
constexpr int kRootRows = 16;

struct Simd {
    static V set1(double a) { return {Half::set1(a), Half::set1(a)}; }
    static V zero() { return {Half::zero(), Half::zero()}; }
    static V load(const double* p) { return {Half::load(p), Half::load(p + 4)}; }
    static void store(double* p, V a) { Half::store(p, a.lo), Half::store(p + 4, a.hi); }
    static V add(V a, V b) { return {Half::add(a.lo, b.lo), Half::add(a.hi, b.hi)}; }
    static V sub(V a, V b) { return {Half::sub(a.lo, b.lo), Half::sub(a.hi, b.hi)}; }
    static V mul(V a, V b) { return {Half::mul(a.lo, b.lo), Half::mul(a.hi, b.hi)}; }
    static V fma(V a, V b, V c) {
        return {Half::fma(a.lo, b.lo, c.lo), Half::fma(a.hi, b.hi, c.hi)};
    }
    static V div(V a, V b) { return {Half::div(a.lo, b.lo), Half::div(a.hi, b.hi)}; }
    static V sqrt(V a) { return {Half::sqrt(a.lo), Half::sqrt(a.hi)}; }
    static V max(V a, V b) { return {Half::max(a.lo, b.lo), Half::max(a.hi, b.hi)}; }
    static V min(V a, V b) { return {Half::min(a.lo, b.lo), Half::min(a.hi, b.hi)}; }
    static M gt(V a, V b) { return {Half::gt(a.lo, b.lo), Half::gt(a.hi, b.hi)}; }
    static M ge(V a, V b) { return {Half::ge(a.lo, b.lo), Half::ge(a.hi, b.hi)}; }
    static M lt(V a, V b) { return {Half::lt(a.lo, b.lo), Half::lt(a.hi, b.hi)}; }
    static V scaleByPow2(V p, V t) {
        return {Half::scaleByPow2(p.lo, t.lo), Half::scaleByPow2(p.hi, t.hi)};
    }
    static M neqOrdered(V a, V b) {
        return {Half::neqOrdered(a.lo, b.lo), Half::neqOrdered(a.hi, b.hi)};
    }
    static M neqUnordered(V a, V b) {
        return {Half::neqUnordered(a.lo, b.lo), Half::neqUnordered(a.hi, b.hi)};
    }
    static M noLanes() { return zero(); }
    static M andNot(M a, M b) { return {Half::andNot(a.lo, b.lo), Half::andNot(a.hi, b.hi)}; }
    static M both(M a, M b) { return {Half::both(a.lo, b.lo), Half::both(a.hi, b.hi)}; }
    static M either(M a, M b) { return {Half::either(a.lo, b.lo), Half::either(a.hi, b.hi)}; }
    static V blend(V a, V b, M m) {
        return {Half::blend(a.lo, b.lo, m.lo), Half::blend(a.hi, b.hi, m.hi)};
    }
    static unsigned bits(M m) { return Half::bits(m.lo) | Half::bits(m.hi) << 4; }
    static M maskOf(unsigned bits) {
        return {Half::maskOf(bits & 15u), Half::maskOf(bits >> 4 & 15u)};
    }
    template <class Read>
    [[gnu::always_inline]] static V lanes(Read read) {
        return {Half::lanes(read), Half::lanes([&](int k) { return read(k + 4); })};
    }
    [[gnu::always_inline]] static V gather(const double* base, const int* index) {
        return {Half::gather(base, index), Half::gather(base, index + 4)};
    }
    [[gnu::always_inline]] static V countsAsDoubles(const std::uint16_t* p) {
        return {Half::countsAsDoubles(p), Half::countsAsDoubles(p + 4)};
    }
    [[gnu::always_inline]] static void loadRun(const double* p, V& x, V& y, V& z) {
        Half::loadRun(p, x.lo, y.lo, z.lo), Half::loadRun(p + 12, x.hi, y.hi, z.hi);
    }
    [[gnu::always_inline]] static void loadPositions(const double* p, const int* index, V& x, V& y,
                                                     V& z) {
        Half::loadPositions(p, index, x.lo, y.lo, z.lo);
        Half::loadPositions(p, index + 4, x.hi, y.hi, z.hi);
    }
    [[gnu::always_inline]] static void storeSlots(double* slot, V fx, V fy, V fz, int stride) {
        Half::storeSlots(slot, fx.lo, fy.lo, fz.lo, stride);
        Half::storeSlots(slot + 4, fx.hi, fy.hi, fz.hi, stride);
    }
};

#include "sim/PairKernelSimd.inc"

}  // namespace avx2x2
#if defined(__clang__)
#pragma clang attribute pop
#pragma clang attribute push(__attribute__((target("avx2,fma,avx512f"))), apply_to = function)
#else
#pragma GCC pop_options
#pragma GCC push_options
#pragma GCC target("avx2,fma,avx512f")
#endif
namespace avx512 {

using V = __m512d;
using M = __mmask8;
constexpr int kLanes = 8;
constexpr int kRootRows = 0;  // PairKernelSimd.inc: each row's root in its pass

// Eight lanes: on CPUs whose dividers are 512 bits wide (AMD Zen 5), twice the ÷ and √ of AVX2
// per instruction. Masks are bits.
struct Simd {
    static V set1(double a) { return _mm512_set1_pd(a); }
    static V zero() { return _mm512_setzero_pd(); }
    static V load(const double* p) { return _mm512_loadu_pd(p); }
    static void store(double* p, V a) { _mm512_storeu_pd(p, a); }
    static V add(V a, V b) { return _mm512_add_pd(a, b); }
    static V sub(V a, V b) { return _mm512_sub_pd(a, b); }
    static V mul(V a, V b) { return _mm512_mul_pd(a, b); }
    static V fma(V a, V b, V c) { return _mm512_fmadd_pd(a, b, c); }
    static V div(V a, V b) { return _mm512_div_pd(a, b); }
    static V sqrt(V a) { return _mm512_sqrt_pd(a); }
    static V max(V a, V b) { return _mm512_max_pd(a, b); }
    static V min(V a, V b) { return _mm512_min_pd(a, b); }
    static M gt(V a, V b) { return _mm512_cmp_pd_mask(a, b, _CMP_GT_OQ); }
    static M ge(V a, V b) { return _mm512_cmp_pd_mask(a, b, _CMP_GE_OQ); }
    static V scaleByPow2(V p, V t) {
        const __m512i whole =
            _mm512_sub_epi64(_mm512_castpd_si512(t), _mm512_set1_epi64(lawexp::kShiftBits));
        const __m512i n1 =
            _mm512_sub_epi64(_mm512_srli_epi64(_mm512_add_epi64(whole, _mm512_set1_epi64(2048)), 1),
                             _mm512_set1_epi64(1024));
        const __m512i n2 = _mm512_sub_epi64(whole, n1), bias = _mm512_set1_epi64(1023);
        const V s1 = _mm512_castsi512_pd(_mm512_slli_epi64(_mm512_add_epi64(n1, bias), 52));
        const V s2 = _mm512_castsi512_pd(_mm512_slli_epi64(_mm512_add_epi64(n2, bias), 52));
        return mul(mul(p, s1), s2);
    }
    static M lt(V a, V b) { return _mm512_cmp_pd_mask(a, b, _CMP_LT_OQ); }
    static M neqOrdered(V a, V b) { return _mm512_cmp_pd_mask(a, b, _CMP_NEQ_OQ); }
    static M neqUnordered(V a, V b) { return _mm512_cmp_pd_mask(a, b, _CMP_NEQ_UQ); }
    static M noLanes() { return 0; }
    static M andNot(M a, M b) { return M(~a & b); }
    static M both(M a, M b) { return M(a & b); }
    static M either(M a, M b) { return M(a | b); }
    static V blend(V a, V b, M m) { return _mm512_mask_blend_pd(m, a, b); }
    static unsigned bits(M m) { return m; }
    static M maskOf(unsigned bits) { return M(bits); }
    template <class Read>
    [[gnu::always_inline]] static V lanes(Read read) {
        return _mm512_setr_pd(read(0), read(1), read(2), read(3), read(4), read(5), read(6),
                              read(7));
    }
    /// base[index[k]] for eight lanes: one hardware gather.
    [[gnu::always_inline]] static V gather(const double* base, const int* index) {
        return _mm512_i32gather_pd(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(index)),
                                   base, 8);
    }
    /// Eight 16-bit counts from p as doubles.
    [[gnu::always_inline]] static V countsAsDoubles(const std::uint16_t* p) {
        return _mm512_cvtepi32_pd(
            _mm256_cvtepu16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p))));
    }
    /// Eight consecutive particles' x, y and z from p (sim/SimdRuns.h).
    [[gnu::always_inline]] static void loadRun(const double* p, V& x, V& y, V& z) {
        loadRun8(p, x, y, z);
    }
    [[gnu::always_inline]] static V join(__m256d low, __m256d high) {
        return _mm512_insertf64x4(_mm512_castpd256_pd512(low), high, 1);
    }
    [[gnu::always_inline]] static void loadPositions(const double* p, const int* index, V& x, V& y,
                                                     V& z) {
        __m256d x0, y0, z0, x1, y1, z1;
        avx2::Simd::loadPositions(p, index, x0, y0, z0);
        avx2::Simd::loadPositions(p, index + 4, x1, y1, z1);
        x = join(x0, x1), y = join(y0, y1), z = join(z0, z1);
    }
    /// The lanes' x, y and z in their row's slots (eight lanes: the slots are in rows).
    [[gnu::always_inline]] static void storeSlots(double* slot, V fx, V fy, V fz, int stride) {
        _mm512_storeu_pd(slot, fx);
        _mm512_storeu_pd(slot + stride, fy);
        _mm512_storeu_pd(slot + 2 * stride, fz);
    }
};

#include "sim/PairKernelSimd.inc"

}  // namespace avx512
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

#endif

#if defined(__x86_64__)
// The SIMD loop for the machine's width, from `begin` (a row's start) to the last whole row.
template <BondLawKind kLaw, bool kTheta, bool kBreak, bool kUpdate, int kN>
int simdPairs(const LinearPairInput& in, const LinearPairOutput& out, int begin, int end,
              double& stiffest) {
    constexpr bool kLookAhead = kLaw == BondLawKind::PowerLaw && kUpdate;
    const bool skipFar = kLookAhead && in.skipFar;
    if (skipFar && simdWidth() == 8)
        return avx512::pairLoopSimd<kLaw, kTheta, kBreak, kUpdate, kLookAhead, kN>(in, out, begin,
                                                                                   end, stiffest);
    if (skipFar && simdWidth() == 4)
        return avx2x2::pairLoopSimd<kLaw, kTheta, kBreak, kUpdate, kLookAhead, kN>(in, out, begin,
                                                                                   end, stiffest);
    if (simdWidth() == 8)
        return avx512::pairLoopSimd<kLaw, kTheta, kBreak, kUpdate, false, kN>(in, out, begin, end,
                                                                              stiffest);
    if (simdWidth() == 4)
        return avx2x2::pairLoopSimd<kLaw, kTheta, kBreak, kUpdate, false, kN>(in, out, begin, end,
                                                                              stiffest);
    return begin;
}
#endif

template <BondLawKind kLaw, bool kTheta, bool kBreak, bool kUpdate>
double pairs(const LinearPairInput& in, const LinearPairOutput& out, int begin, int end) {
    double stiffest = in.stiffestKnown;
#if defined(__x86_64__)
    // The eight-lane loops take whole rows (PairKernelSimd.inc's laneOf): the pairs before the
    // first row's start, if any, one by one.
    if (simdWidth() >= 4 && begin % kPairTile != 0) {
        const int row = std::min(end, begin + kPairTile - begin % kPairTile);
        stiffest = std::max(stiffest, pairLoop<kLaw, kTheta, kBreak, kUpdate>(in, out, begin, row));
        begin = row;
    }
    // The power law's exponent is 2, 3 or 4 here (PeridynamicBonds::vectorised).
    if constexpr (kLaw != BondLawKind::PowerLaw)
        begin = simdPairs<kLaw, kTheta, kBreak, kUpdate, 0>(in, out, begin, end, stiffest);
    else if (in.powerN == 2.0)
        begin = simdPairs<kLaw, kTheta, kBreak, kUpdate, 2>(in, out, begin, end, stiffest);
    else if (in.powerN == 3.0)
        begin = simdPairs<kLaw, kTheta, kBreak, kUpdate, 3>(in, out, begin, end, stiffest);
    else if (in.powerN == 4.0)
        begin = simdPairs<kLaw, kTheta, kBreak, kUpdate, 4>(in, out, begin, end, stiffest);
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

bool slotRows() { return simdWidth() >= 4; }

double pairApproachRate(const LinearPairInput& in, const ApproachRate& a, int begin, int end) {
    double fastest = 0.0;
#if defined(__x86_64__)
    for (; begin < end && begin % kPairTile != 0; ++begin)  // whole rows, as pairs()
        fastest = std::max(fastest, approachOf(in, a, begin));
    if (simdWidth() == 8)
        begin = in.theta ? avx512::approachSimd<true>(in, a, begin, end, fastest)
                         : avx512::approachSimd<false>(in, a, begin, end, fastest);
    else if (simdWidth() == 4)
        begin = in.theta ? avx2::approachSimd<true>(in, a, begin, end, fastest)
                         : avx2::approachSimd<false>(in, a, begin, end, fastest);
#endif
    for (int u = begin; u < end; ++u) fastest = std::max(fastest, approachOf(in, a, u));
    return fastest;
}

double flaggedApproachRate(const LinearPairInput& in, const ApproachRate& a,
                           const std::uint8_t* approaching, int begin, int end) {
    double fastest = 0.0;
    for (int row = begin / kPairTile; row * kPairTile < end; ++row) {
        std::uint64_t eight = 0;  // 64 pairs at once where none is flagged
        if ((row + 8) * kPairTile <= end &&
            (std::memcpy(&eight, &approaching[row], 8), eight == 0)) {
            row += 7;
            continue;
        }
        for (unsigned bits = approaching[row]; bits != 0; bits &= bits - 1) {
            const int u = kPairTile * row + std::countr_zero(bits);
            if (u >= begin && u < end) fastest = std::max(fastest, approachOf(in, a, u));
        }
    }
    return fastest;
}

double largestMagnitude(const double* p, std::size_t n) {
#if defined(__x86_64__)
    if (simdWidth() == 8) return avx512::largestMagnitude(p, n);
    if (simdWidth() == 4) return avx2::largestMagnitude(p, n);
#endif
    double largest = 0.0;
    for (std::size_t k = 0; k < n; ++k) largest = std::max(largest, std::fabs(p[k]));
    return largest;
}

double largestChange(const double* before, const double* after, std::size_t n) {
#if defined(__x86_64__)
    if (simdWidth() == 8) return avx512::largestChange(before, after, n);
    if (simdWidth() == 4) return avx2::largestChange(before, after, n);
#endif
    double largest = 0.0;
    for (std::size_t k = 0; k < n; ++k)
        largest = std::max(largest, std::fabs(after[k] - before[k]));
    return largest;
}

double lookAheadSlack(double largest, double dt) {
    // 1e-100: a sheet at rest still gets a positive slack, far from any underflow of the tests.
    const double slack = dt * (2.0 * std::sqrt(3.0) * (1.0 + 0x1p-20)) * std::max(largest, 1e-100);
    return slack <= std::numeric_limits<double>::max() ? slack
                                                       : std::numeric_limits<double>::infinity();
}

void lawExpLanes(const double* x, double* y, int n) {
#if defined(__x86_64__)
    if (simdWidth() == 8) return avx512::expLanes(x, y, n);
    if (simdWidth() == 4) return avx2::expLanes(x, y, n);
#endif
    for (int k = 0; k < n; ++k) y[k] = lawExp(x[k]);
}

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

}  // namespace rend::sim
