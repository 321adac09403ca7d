// The mass-spring paper's bubble inflation test (seeds/003, Sec. 5 and 7): a latex disc,
// D = 75 mm, h = 0.35 mm, nu = 0.45, clamped at its rim and inflated by 5000, 7300 and 8940 Pa.
// The paper fits E to its own experiment (a secant modulus against strain, not printed); we
// take a constant E = 1.5 MPa, a secant modulus of latex at these strains, and compare each
// solver's bubble height with Hencky's solution at nu = 0.45, C = 0.6112 (computed,
// checks/HenckyConstant.h). The bubbles rise to about half the radius, beyond Foppl-Hencky's
// moderate deflections: the geometrically exact solvers must agree with each other, and all sit
// above Hencky by the finite-deflection term (bench/accuracy/hencky.cpp measures K (w0/a)^2).

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <utility>

#include "tests/validation/checks/Hencky.h"
#include "tests/validation/checks/HenckyConstant.h"

using namespace rend::checks;

namespace {

constexpr double kNu = 0.45, kE = 1.5e6, kH = 0.35e-3, kRadius = 0.0375, kDx = 1.5e-3;

struct Row {
    std::string solver;
    const char* name;
};
constexpr Row kSolvers[] = {{"fem_cst", "fem_cst"},
                            {"mass_spring_tp", "mass_spring_tp"},
                            {"mass_spring_vg", "mass_spring_vg"},
                            {"mpm", "mpm"}};

/// Bubble height and Hencky's, at `pressure`.
std::pair<double, double> bubble(std::string solver, double pressure) {
    DiscSpec spec;
    spec.radius = kRadius + 2 * kDx;  // the clamped ring lies outside a = 37.5 mm
    spec.dx = kDx;
    spec.load = pressure;
    spec.solver = solver;
    spec.youngsModulus = kE;
    spec.poissonRatio = kNu;
    spec.thickness = kH;
    spec.density = 1000;
    const Result r = clampedDisc(spec);
    const double hencky =
        henckyConstant(kNu) / kHenckyC * henckyDeflection(r.attached, pressure, kE * kH);
    return {r.w0, hencky};
}

}  // namespace

TEST(ValidationBubble, SmallBubblesMatchHenckyAtNuPoint45WhereTheSolverCarriesNu) {
    // At w0/a = 0.1 Hencky's theory holds (its finite-deflection departure is ~0.5%): the FEM
    // and the two-parameter springs, which carry nu = 0.45, land within 2%; Van Gelder's
    // central springs cannot (nu = 1/3 is built into a spring network) and are reported.
    EXPECT_NEAR(henckyConstant(kNu), 0.6112, 1e-4);
    const double load = std::pow(0.1 / henckyConstant(kNu), 3) * kE * kH / kRadius;
    for (const Row& s : kSolvers) {
        const auto [w0, hencky] = bubble(s.solver, load);
        std::printf("bubble w0/a = 0.1 (p = %.0f Pa), %-15s: %.4f mm, Hencky %.4f mm, %+.2f%%\n",
                    load, s.name, 1e3 * w0, 1e3 * hencky, 100 * (w0 / hencky - 1));
        if (s.solver != "mass_spring_vg") {
            EXPECT_NEAR(w0 / hencky, 1.0, 0.02) << s.name;
        }
    }
}

TEST(ValidationBubble, ThePapersPressuresRaiseBubblesBeyondHenckysRange) {
    // The paper's 5000, 7300 and 8940 Pa raise bubbles to half the radius (its h < a
    // condition holds). There Hencky is only a guide: the geometrically exact solvers all stand
    // above it, and their constitutive laws part (St. Venant-Kirchhoff stiffens on the Green
    // strain, the springs are linear in the stretch), as on the pressurised sphere.
    for (double pressure : {5000.0, 7300.0, 8940.0})
        for (const Row& s : kSolvers) {
            const auto [w0, hencky] = bubble(s.solver, pressure);
            std::printf(
                "bubble p = %4.0f Pa, %-15s: height %.3f mm (h/a %.2f), Hencky %.3f mm, %+.1f%%\n",
                pressure, s.name, 1e3 * w0, w0 / kRadius, 1e3 * hencky, 100 * (w0 / hencky - 1));
            EXPECT_GT(w0, hencky) << s.name << ": the finite-deflection term is positive";
            EXPECT_LT(w0, kRadius) << s.name << ": h < a, the paper's condition";
        }
}
