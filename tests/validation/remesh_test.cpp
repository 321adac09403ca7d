// Seed 004's figure for the particle solvers (sim/Remesh.h): the angular momentum of a spinning
// free disc against the remeshing frequency. Seed 004's SPH (updated Lagrangian, Gingold and
// Monaghan's equations) does not conserve it, and remeshing made it better. rend's SPH and
// bonds are the exact gradients of rotation-invariant energies, so they conserve it to
// round-off without remeshing; remeshing refits the non-affine part of the motion (the disc's
// breathing) and loses some, the more the more often. The set-up is checks/Mpm.h's
// spinningSheet(disc): radius 0.2 m, dx 0.02, spun at 3.16 rad/s (10% strain), 4000 steps.

#include <gtest/gtest.h>

#include <cstdio>

#include "tests/validation/checks/Mpm.h"

using namespace rend::checks;

TEST(ValidationRemesh, ASpinningDiscsAngularMomentumAgainstTheRemeshingFrequency) {
    for (const char* solver : {"sph", "peridynamic"}) {
        double previous = 1.0;
        for (const int every : {1, 10, 100}) {
            const SpinFigures f = spinningSheet(solver, 4000, {}, true, every);
            std::printf(
                "spinning disc, %s, remesh every %3d steps: |L - L0| / L0 %.3e, KE / KE0 "
                "%.4f\n",
                solver, every, f.angularMomentumDrift, f.kineticEnergyRatio);
            EXPECT_LT(f.angularMomentumDrift, previous) << solver << " rarer remeshing loses less";
            previous = f.angularMomentumDrift;
        }
        EXPECT_LT(previous, 5e-3) << solver << " every 100 steps";
        const SpinFigures never = spinningSheet(solver, 4000, {}, true, 0);
        std::printf("spinning disc, %s, never remeshed: |L - L0| / L0 %.3e, KE / KE0 %.4f\n",
                    solver, never.angularMomentumDrift, never.kineticEnergyRatio);
        EXPECT_LT(never.angularMomentumDrift, 1e-12) << solver;
    }
}
