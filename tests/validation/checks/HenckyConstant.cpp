#include "tests/validation/checks/HenckyConstant.h"

#include <array>

namespace rend::checks {
namespace {

struct Shot {
    double rimMismatch;  ///< n'(1) - (nu - 1) n(1)
    double constant;     ///< int_0^1 rho / (2 n)
};

Shot shoot(double n0, double nu) {
    constexpr int kSteps = 4000;
    constexpr double kStart = 1e-4;
    auto slope = [](double rho, const std::array<double, 2>& y) {
        return std::array<double, 2>{y[1], -3.0 * y[1] / rho - 1.0 / (8.0 * y[0] * y[0])};
    };
    std::array<double, 2> y = {n0 - kStart * kStart / (64 * n0 * n0), -2 * kStart / (64 * n0 * n0)};
    const double h = (1.0 - kStart) / kSteps;
    double rho = kStart, integral = kStart * kStart / (4 * n0);
    for (int k = 0; k < kSteps; ++k) {
        auto at = [&](const std::array<double, 2>& d, double f) {
            return std::array<double, 2>{y[0] + f * d[0], y[1] + f * d[1]};
        };
        const auto k1 = slope(rho, y);
        const auto k2 = slope(rho + h / 2, at(k1, h / 2));
        const auto k3 = slope(rho + h / 2, at(k2, h / 2));
        const auto k4 = slope(rho + h, at(k3, h));
        const std::array<double, 2> next = {y[0] + h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]),
                                            y[1] + h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])};
        integral += h * 0.5 * (rho / (2 * y[0]) + (rho + h) / (2 * next[0]));
        y = next;
        rho += h;
    }
    return {y[1] - (nu - 1.0) * y[0], integral};
}

}  // namespace

double henckyConstant(double poissonRatio) {
    double lo = 0.05, hi = 3.0;
    const bool loPositive = shoot(lo, poissonRatio).rimMismatch > 0;
    for (int k = 0; k < 100; ++k) {
        const double mid = 0.5 * (lo + hi);
        ((shoot(mid, poissonRatio).rimMismatch > 0) == loPositive ? lo : hi) = mid;
    }
    return shoot(0.5 * (lo + hi), poissonRatio).constant;
}

}  // namespace rend::checks
