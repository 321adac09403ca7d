// VALIDATION.md, "Griffith centre crack, half length a >= 10 delta: sigma_c = sqrt(E G_f / (pi a)),
// within 15%". The pulled centre-cracked plate is explained in checks/Griffith.h.

#include "tests/validation/checks/Griffith.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>

using namespace rend::checks;

TEST(Griffith, CentreCrackGrowsAtTheGriffithStress) {
    // Reference: VALIDATION.md "Griffith centre crack", sigma_c = sqrt(E G_f / (pi a)) for
    // a >= 10 delta; target within 15%, checked at R = 3 dx. At the paper's R = 1.5 dx (one ring
    // of neighbours: a lattice, not a continuum) the notch tip is trapped until 1.77 x sigma_c
    // (3.1 G_f) whatever a / delta is (also 1.79 at a = 20 delta); printed, not checked.
    struct Case {
        CentreCrack crack;
        bool checked;
    };
    for (const Case& k :
         {Case{{10.0, 0.01, 1.5, 6, 4, 10}, false}, Case{{10.0, 0.01, 3.0, 6, 4, 10}, true}}) {
        const auto t0 = std::chrono::steady_clock::now();
        const Onset o = pullCentreCrack(k.crack);
        const double wall =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        ASSERT_TRUE(o.grew) << "the crack never grew";
        const double griffith = griffithStress(k.crack);
        const double feddersen = feddersenStress(k.crack);
        std::printf(
            "[griffith] R = %.1f dx, a = %.0f delta, plate %.0fa x %.0fa (%d particles, %.1f s): "
            "crack grows at t = %.3f s (step %ld); "
            "far-field sigma_yy = %.3f Pa (reaction %.3f Pa, kinetic/strain energy %.2e); "
            "Griffith %.3f Pa -> %.4f (error %+.1f%%); with the width correction "
            "%.3f Pa -> %.4f\n",
            k.crack.factor, k.crack.horizons, k.crack.widthOverA, k.crack.heightOverA, o.particles,
            wall, o.seconds, o.steps, o.bandStress, o.reactionStress, o.kineticShare, griffith,
            o.bandStress / griffith, 100.0 * (o.bandStress / griffith - 1.0), feddersen,
            o.bandStress / feddersen);
        EXPECT_NEAR(o.reactionStress / o.bandStress, 1.0, 0.03) << "quasi-static: one stress";
        if (k.checked) {
            EXPECT_NEAR(o.bandStress / griffith, 1.0, 0.15);
        }
    }
}
