// VALIDATION.md, "pressurised thin sphere" and the mass-spring paper's Table 1; the set-up and
// the closed forms are in checks/Sphere.h.

#include "tests/validation/checks/Sphere.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace rend::checks;

TEST(ValidationSphere, EachSolverMatchesItsClosedFormAndTheTableOfTheMassSpringPaper) {
    const double dx = 0.1;
    const double paperVg[] = {-0.65, -0.48, -0.27}, paperTp[] = {-0.29, -0.19, -0.08};
    std::printf("pressurised sphere R = 1 m, p = 10 kPa, nu = 0.3 (mass-spring paper, Table 1)\n");
    for (int c = 0; c < 3; ++c) {
        const Material& mat = kCases[c];
        const double reference = logStrainStretch(mat);
        const struct {
            std::string solver;
            const char* name;
        } rows[] = {{"fem_cst", "fem_cst"},
                    {"mass_spring_vg", "mass_spring_vg"},
                    {"mass_spring_tp", "mass_spring_tp"},
                    {"mpm", "mpm"}};
        std::printf("E = %.0f MPa, h = %.1f mm: log-strain reference %.5f\n", mat.E / 1e6,
                    mat.h * 1e3, reference);
        for (const auto& row : rows) {
            const SphereResult r = inflate(row.solver, mat, dx);
            const double closedForm = closedFormStretch(row.solver, mat);
            const double own = r.stretch / closedForm - 1;
            const double vsReference = r.stretch / reference - 1;
            std::printf(
                "  %-15s %d particles: lambda %.5f, own closed form %.5f (%+.3f%%), against the "
                "log-strain reference %+.2f%% (paper: VG %+.2f%%, TP %+.2f%%); radius at the "
                "5-valent / 6-valent vertices %.4f / %.4f\n",
                row.name, r.particles, r.stretch, closedForm, 100 * own, 100 * vsReference,
                paperVg[c], paperTp[c], r.fiveValent, r.sixValent);
            EXPECT_LT(std::abs(own), 1e-3) << row.name << " case " << c;
            if (row.solver == "mass_spring_tp") {
                EXPECT_LE(std::abs(vsReference), std::abs(paperTp[c]) / 100 + 2e-4) << c;
            }
        }
    }
}
