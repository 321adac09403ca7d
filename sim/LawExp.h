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
/// kShift's bits: t = x log2e + kShift holds n = round(x log2e) as bits(t) - kShiftBits.
inline constexpr std::int64_t kShiftBits = 0x4338000000000000;

}  // namespace rend::sim::lawexp

namespace rend::sim {

/// e^x, the same bits as the vector kernels' (see above).
double lawExp(double x);

}  // namespace rend::sim
