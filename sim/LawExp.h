#pragma once
// e^x with the same bits in a scalar loop and in every vector width (sim/PairKernelSimd.inc
// has the vector form, operation for operation): eq. 20's decay, evaluated eight bonds at a time
// and one at a time alike. Cody and Waite's reduction x = n ln 2 + r, |r| <= ln 2 / 2, then
// e^r by its Taylor series to r^13 (its remainder under 0.02 ulp) in Estrin's form, and 2^n
// as two exact powers of two. Within 2 ulp of the correctly rounded e^x (tests/sim/
// law_exp_test.cpp); 0 below -746, +inf above 710, NaN for NaN.

#include <cstdint>

namespace rend::sim::lawexp {

inline constexpr double kLog2e = 1.4426950408889634;     // 1 / ln 2
inline constexpr double kShift = 0x1.8p52;               // adding it rounds to an integer
inline constexpr double kLn2Hi = 0x1.62e42fee00000p-1;   // ln 2's first 32 bits: n kLn2Hi exact
inline constexpr double kLn2Lo = 0x1.a39ef35793c76p-33;  // ln 2 - kLn2Hi
inline constexpr double kLowest = -746.0, kHighest = 710.0;
inline constexpr int kTerms = 13;
/// 1 / k! for k = 0 ... kTerms.
inline constexpr auto kInverseFactorial = [] {
    struct Table {
        double c[kTerms + 1];
    } t{};
    double f = 1.0;
    for (int k = 0; k <= kTerms; ++k) {
        if (k > 0) f *= k;
        t.c[k] = 1.0 / f;
    }
    return t;
}();
/// e^r's series to r^kTerms in Estrin's form, with fused multiply-adds: the pairs of terms, then
/// pairs of those by r^2, r^4 and r^8, so that its longest chain is four fused steps instead of
/// Horner's thirteen multiplies and thirteen adds (eq. 20's kernel rows wait on it). `Ops` is a
/// width's operations (set1, mul, fma: a scalar's or a vector's), in this order at every width:
/// the same bits.
template <class Ops, class V>
[[gnu::always_inline]] inline V estrin(V r) {
    static_assert(kTerms == 13, "the pairing below is for fourteen terms");
    const auto& c = kInverseFactorial.c;
    const V r2 = Ops::mul(r, r), r4 = Ops::mul(r2, r2), r8 = Ops::mul(r4, r4);
    const V a0 = Ops::fma(Ops::set1(c[1]), r, Ops::set1(c[0]));
    const V a1 = Ops::fma(Ops::set1(c[3]), r, Ops::set1(c[2]));
    const V a2 = Ops::fma(Ops::set1(c[5]), r, Ops::set1(c[4]));
    const V a3 = Ops::fma(Ops::set1(c[7]), r, Ops::set1(c[6]));
    const V a4 = Ops::fma(Ops::set1(c[9]), r, Ops::set1(c[8]));
    const V a5 = Ops::fma(Ops::set1(c[11]), r, Ops::set1(c[10]));
    const V a6 = Ops::fma(Ops::set1(c[13]), r, Ops::set1(c[12]));
    const V b0 = Ops::fma(a1, r2, a0), b1 = Ops::fma(a3, r2, a2), b2 = Ops::fma(a5, r2, a4);
    const V d0 = Ops::fma(b1, r4, b0), d1 = Ops::fma(a6, r4, b2);
    return Ops::fma(d1, r8, d0);
}
/// x's reduction for e^x = 2^n e^r: t = x log2e + kShift, holding n in its low bits, and
/// r = x - n ln 2 (n kLn2Hi and x less it exact, then the rest of ln 2), by fused multiply-adds.
template <class Ops, class V>
[[gnu::always_inline]] inline void reduce(V x, V& t, V& r) {
    t = Ops::fma(x, Ops::set1(kLog2e), Ops::set1(kShift));
    const V n = Ops::sub(t, Ops::set1(kShift));
    r = Ops::fma(n, Ops::set1(-kLn2Lo), Ops::fma(n, Ops::set1(-kLn2Hi), x));
}
/// kShift's bits: t = x log2e + kShift holds n = round(x log2e) as bits(t) - kShiftBits.
inline constexpr std::int64_t kShiftBits = 0x4338000000000000;

}  // namespace rend::sim::lawexp

namespace rend::sim {

/// e^x, the same bits as the vector kernels' (see above).
double lawExp(double x);

}  // namespace rend::sim
