// sim/LawExp.h's e^x: within 2 ulp of the C library's over the whole range where e^x is a
// normal number, exact at 0, and the right answer at the ends (0, subnormals, +inf, NaN).

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "sim/LawExp.h"
#include "sim/PairKernels.h"
#include "sim/Random.h"

using namespace rend::sim;

namespace {

/// How many doubles lie between a and b (both finite, the same sign).
std::int64_t ulpsApart(double a, double b) {
    return std::abs(std::bit_cast<std::int64_t>(a) - std::bit_cast<std::int64_t>(b));
}

TEST(LawExp, IsWithinTwoUlpOfTheLibrarysOverItsRange) {
    std::int64_t worst = 0;
    for (int k = 0; k < 200000; ++k) {
        const double x = -708.0 + 1417.0 * uniformFromHash(21, k);
        worst = std::max(worst, ulpsApart(lawExp(x), std::exp(x)));
    }
    for (int k = 0; k < 20000; ++k) {  // eq. 20's arguments: -beta (eta - eta0) / eta0
        const double x = -50.0 * uniformFromHash(22, k);
        worst = std::max(worst, ulpsApart(lawExp(x), std::exp(x)));
    }
    EXPECT_LE(worst, 2);
}

TEST(LawExp, AnswersAtTheEnds) {
    const double inf = std::numeric_limits<double>::infinity();
    EXPECT_EQ(lawExp(0.0), 1.0);
    EXPECT_EQ(lawExp(-0.0), 1.0);
    EXPECT_EQ(lawExp(710.0), inf);
    EXPECT_EQ(lawExp(1e300), inf);
    EXPECT_EQ(lawExp(inf), inf);
    EXPECT_EQ(lawExp(-746.0), 0.0);
    EXPECT_EQ(lawExp(-1e300), 0.0);
    EXPECT_EQ(lawExp(-inf), 0.0);
    EXPECT_TRUE(std::isnan(lawExp(std::nan(""))));
    for (const double x : {-709.5, -720.0, -740.0, -745.0}) {  // subnormal results
        const double expected = std::exp(x), got = lawExp(x);
        EXPECT_NEAR(got, expected, 2e-16 * expected + 5e-324) << x;
    }
    EXPECT_LE(ulpsApart(lawExp(709.7), std::exp(709.7)), 2);
    EXPECT_LE(ulpsApart(lawExp(1.0), std::exp(1.0)), 1);
}

// The elastoplastic kernel's vector form (ctest's kernels.* run this at every width).
TEST(LawExp, TheKernelsLanesHaveItsBits) {
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<double> x = {0.0,    -0.0, 1.0,          -1.0,   709.7,  710.0,
                             800.0,  inf,  -708.0,       -720.0, -745.0, -746.0,
                             -1e300, -inf, std::nan(""), 1e-300, -3.5,   2.25};
    for (int k = 0; k < 1000; ++k) x.push_back(-800.0 + 1600.0 * uniformFromHash(23, k));
    std::vector<double> lanes(x.size());
    lawExpLanes(x.data(), lanes.data(), int(x.size()));
    for (std::size_t k = 0; k < x.size(); ++k) {
        const double one = lawExp(x[k]);
        EXPECT_EQ(std::bit_cast<std::uint64_t>(lanes[k]), std::bit_cast<std::uint64_t>(one))
            << "x = " << x[k];
    }
}

}  // namespace
