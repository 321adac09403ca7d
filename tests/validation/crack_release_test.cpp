// VALIDATION.md "fracture energy" for every solver: energy released by the breaking per unit new
// crack length against G_f, booked solver-agnostically (checks/CrackRelease.h) on the pulled,
// long-notched strip of checks/FractureEnergy.h. The peridynamic-only per-bond booking is
// fracture_energy_test.cpp.
//
// Measured at dx = 0.01 (R = 1.5 dx), far end held, G/G_f at dt = 0.8 / 0.4 / 0.2 x the stable
// bound (bench_accuracy --only fracture_energy_solvers), onset = grip strain at the first release
// over the strip's Griffith strain:
//   peridynamic   1.032 / 0.970 / 0.939   onset 1.82   (row share 0.907 x overshoot)
//   fem_cst       1.156 / 1.097 / 1.077   onset 1.60   (at the springs' strain 0.637 / 0.619 /
//                                                      0.599, onset 1.21: see bandCriticalStrain)
//   mass_spring_vg 1.131 / 1.066 / 1.034   onset 1.90   (row share 1 x overshoot)
//   mass_spring_tp 1.131 / 1.077 / 1.059   onset 1.65   (springs' strain: 0.645 / 0.623 / 0.606)
//   sph           no single crack: 50-160 lattice edges break at the grips and most of the
//                 rest off the notch's line, whatever dt, damping or the far end; onset 2.00.
// The overshoot: a bond breaks at the first step that finds it past its critical strain, and at
// the running crack's tip that strain grows fast, so it holds (eta/eta_c)^2 = 1.136 / 1.061 /
// 1.032 of the calibrated energy: first order in dt, the booking tends to the calibration.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>

#include "tests/validation/checks/CrackRelease.h"

using namespace rend::sim;
using namespace rend::checks;

namespace {

struct Window {
    double start, end;
};

Window windowOf(const NotchedStrip& s) {
    return {s.notchTip + 5 * s.dx, 0.5 * s.width - 15 * s.dx};
}

}  // namespace

TEST(CrackRelease, PeridynamicReleaseIsEachBrokenBondsEnergyAtItsStretch) {
    // With the bonds the release must be the per-bond booking of runCrack (at eta_c) times the
    // broken bonds' mean (eta/eta_c)^2 at x_n, to rounding: that the release books exactly the
    // broken bonds at the positions where they broke validates the method. Every broken bond is
    // past eta_c at x_n (Membrane::step breaks at x_n with symplectic Euler), and the overshoot
    // is first order in dt: measured (eta/eta_c)^2 - 1 = 0.136 at 0.8 and 0.061 at 0.4.
    double excess[2] = {0.0, 0.0};
    for (int k = 0; k < 2; ++k) {
        NotchedStrip s;
        s.timeStepSafety = k == 0 ? 0.8 : 0.4;
        const Window w = windowOf(s);
        const ReleaseRecord r = runCrackRelease(s, w.start, w.end);
        const CrackRecord c = runCrack(s, w.start, w.end);
        ASSERT_TRUE(r.reached && c.reached);
        std::printf(
            "[crack release] pd, dt = %.1f x bound: release %.4f G_f, per bond at eta_c %.4f G_f, "
            "ratio %.6f, mean (eta/eta_c)^2 %.6f, smallest eta/eta_c %.5f\n",
            s.timeStepSafety, releasedPerLength(s, r), energyPerLength(s, c), r.released / c.energy,
            r.overshoot, r.minBreakStretch);
        EXPECT_EQ(r.broken, c.broken) << "the same run, so the same bonds";
        EXPECT_NEAR(r.released / c.energy, r.overshoot, 1e-9 * r.overshoot);
        EXPECT_GE(r.minBreakStretch, 1.0) << "a bond broke before it reached eta_c at x_n";
        excess[k] = r.overshoot - 1.0;
    }
    EXPECT_GT(excess[1], 0.0);
    EXPECT_NEAR(excess[1] / excess[0], 0.5, 0.15) << "overshoot first order in dt";
}

TEST(CrackRelease, EverySolverReleasesItsMeasuredShareOfTheFractureEnergy) {
    struct Case {
        std::string solver;
        double safety;
        double low, high;  ///< the measured band of released energy per length over G_f
        bool straight;     ///< one crack along the notch's line, nothing at the grips
    };
    const Case cases[] = {
        // VALIDATION.md's 10%: the bonds' row share 0.907 times the overshoot 1.036.
        {"peridynamic", 0.2, 0.90, 1.10, true},
        // An element releases only its own energy, about E' eps_c^2 / 2 over the band of
        // elements the crack takes out (sqrt(3)/2 dx high). At the springs' critical strain
        // that was (1 - nu^2)^-1 / 2 = 0.56 G_f (measured 0.599); bandCriticalStrain's
        // sqrt(2 (1 - nu^2)) = 4/3 makes it 1.077 (the overshoot included).
        {"fem_cst", 0.2, 0.90, 1.10, true},
        // Calibrated on exactly these springs: 1 times the overshoot 1.034.
        {"mass_spring_vg", 0.2, 0.90, 1.10, true},
        // A broken side takes its two triangles with it, a band as the FEM's: at the springs'
        // strain 0.606 G_f, with bandCriticalStrain 1.059.
        {"mass_spring_tp", 0.2, 0.90, 1.10, true},
        // No single crack (see the top): only the onset is checked. dt = 0.8 x the bound: at 0.2
        // it takes 40 s and does no better.
        {"sph", 0.8, 0.0, 0.0, false},
    };
    for (const Case& k : cases) {
        NotchedStrip s;
        s.solver = k.solver;
        s.holdFarEnd = true;
        s.timeStepSafety = k.safety;
        const Window w = windowOf(s);
        const auto t0 = std::chrono::steady_clock::now();
        const ReleaseRecord r = runCrackRelease(s, w.start, w.end);
        const double wall =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const double g = releasedPerLength(s, r);
        std::printf(
            "[crack release] %-12s dt = %.1f x bound: %s; released %.4f G_f (window %.4f), "
            "onset %.3f x Griffith; %zu bonds broken near the line (%zu off it), %zu at the "
            "grips; %.1f s\n",
            k.solver.c_str(), k.safety, r.reached ? "ran through" : "did not run through", g,
            r.reached ? releasedPerLength(s, r, true) : NAN, r.strainAtStart, r.broken, r.offLine,
            r.elsewhere, wall);
        SCOPED_TRACE(k.solver.c_str());
        // Energy balance: once the notch is longer than the strip is high the strip releases
        // onset^2 G_f per unit length, so the crack cannot run on less than it dissipates. The
        // lattice traps the tip up to about 2 x Griffith (griffith_test.cpp).
        EXPECT_GE(r.strainAtStart * r.strainAtStart, k.straight ? g : 1.0);
        EXPECT_LE(r.strainAtStart, 2.1);
        if (!k.straight) continue;
        ASSERT_TRUE(r.reached);
        EXPECT_EQ(r.offLine, 0u);
        EXPECT_EQ(r.elsewhere, 0u);
        EXPECT_EQ(r.negativeReleased, 0.0) << "breaking only ever releases energy";
        EXPECT_GE(g, k.low);
        EXPECT_LE(g, k.high);
        EXPECT_NEAR(releasedPerLength(s, r, true), g, 0.02) << "a steady crack";
    }
}
