#include "sim/LawExp.h"

#include <bit>
#include <cmath>

namespace rend::sim {

namespace {

struct ScalarOps {
    static double set1(double a) { return a; }
    static double add(double a, double b) { return a + b; }
    static double sub(double a, double b) { return a - b; }
    static double mul(double a, double b) { return a * b; }
    static double fma(double a, double b, double c) { return std::fma(a, b, c); }
};

#include "sim/LawExpSteps.inc"

}  // namespace

double lawExp(double x) {
    using namespace lawexp;
    if (std::isnan(x)) return x;
    x = std::min(std::max(x, kLowest), kHighest);
    double t, r;
    reduce<ScalarOps>(x, t, r);
    const double p = estrin<ScalarOps>(r);
    // 2^n as 2^n1 2^n2, n1 = floor(n / 2): each a normal number, so that only the last product
    // rounds (to a subnormal, 0 or infinity where e^x is one).
    const std::int64_t whole = std::bit_cast<std::int64_t>(t) - kShiftBits;
    const std::int64_t n1 = std::int64_t(std::uint64_t(whole + 2048) >> 1) - 1024, n2 = whole - n1;
    const double s1 = std::bit_cast<double>(std::uint64_t(n1 + 1023) << 52);
    const double s2 = std::bit_cast<double>(std::uint64_t(n2 + 1023) << 52);
    return p * s1 * s2;
}

}  // namespace rend::sim
