// Issue 15: the MPM solver (sim/Mpm.h) validated like the others. Its statics are the FEM's
// lattice forces (ValidationBimaterial, ValidationSphere take it as such); these are the checks
// the grid transfer could fail. The set-ups are in checks/Mpm.h.

#include "tests/validation/checks/Mpm.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace rend::checks;

TEST(ValidationMpm, APlaneWaveTravelsAtCpWithinTwoPercentAndConvergesUnderRefinement) {
    const WaveFigures coarse = planeWave("mpm", 0.04, 0.3), fine = planeWave("mpm", 0.02, 0.3);
    std::printf("mpm P wave, nu = 0.3: speed / c_p %.4f at dx 0.04 (%d particles), %.4f at 0.02\n",
                coarse.speedOverCp, coarse.particles, fine.speedOverCp);
    EXPECT_NEAR(coarse.speedOverCp, 1.0, 0.02);
    EXPECT_NEAR(fine.speedOverCp, 1.0, 0.02);
    EXPECT_LT(std::abs(fine.speedOverCp - 1.0), std::abs(coarse.speedOverCp - 1.0));
}

TEST(ValidationMpm, TheBimaterialStripFollowsTheFemWithinTwoPercentAndConverges) {
    const PullFigures slow = pulledBimaterial("mpm", 0.04);
    std::printf(
        "mpm bimaterial strip, quasi-static pull: max |u - u_fem| / max |u_fem| %.2e, "
        "soft / stiff strain %.3f, %d of %d particles enriched\n",
        slow.worstDifference, slow.softOverStiff, slow.enriched, slow.particles);
    EXPECT_LT(slow.worstDifference, 0.02);
    const PullFigures coarse = pulledBimaterial("mpm", 0.04, {}, true);
    const PullFigures fine = pulledBimaterial("mpm", 0.02, {}, true);
    std::printf(
        "mpm bimaterial strip, jerked: max |u - u_fem| / max |u_fem| %.4f at dx 0.04, "
        "%.4f at 0.02\n",
        coarse.worstDifference, fine.worstDifference);
    EXPECT_LT(coarse.worstDifference, 0.02);
    EXPECT_LT(fine.worstDifference, 0.6 * coarse.worstDifference) << "converges";
}

// Seed 002's Fig. 3: two materials within one grid cell. The plain grid averages their motion;
// the enrichment solves them on their own domains.
TEST(ValidationMpm, EnrichmentKeepsTwoMaterialsInOneCellApart) {
    rend::sim::MpmParams plain, enriched;
    plain.grid = enriched.grid = 1.0;
    plain.enrich = false;
    const PullFigures averaged = pulledStripes(0.02, 0.04, plain);
    const PullFigures apart = pulledStripes(0.02, 0.04, enriched);
    std::printf(
        "stripes 2 dx wide in a grid of dx: against the FEM, plain MPM %.4f, enriched "
        "%.2e (%d of %d particles enriched)\n",
        averaged.worstDifference, apart.worstDifference, apart.enriched, apart.particles);
    EXPECT_GT(averaged.worstDifference, 0.02);
    EXPECT_LT(apart.worstDifference, 1e-3);
}

// Seed 004's figure for the MPM: a free sheet spun about its normal keeps its angular momentum
// (APIC's affine spin counted), as the Lagrangian solvers do.
TEST(ValidationMpm, ASpinningFreeSheetKeepsItsAngularMomentum) {
    for (const char* solver : {"mpm", "fem_cst", "peridynamic"}) {
        const SpinFigures f = spinningSheet(solver, 2000);
        std::printf("spinning sheet, %s, 2000 steps: |L - L0| / L0 %.2e, KE / KE0 %.4f\n", solver,
                    f.angularMomentumDrift, f.kineticEnergyRatio);
        EXPECT_LT(f.angularMomentumDrift, 1e-9) << solver;
    }
}

// The grid's collision, measured against self-contact: a piece dropped on another.
TEST(ValidationMpm, ContactKeepsAPieceOnTheOneBelowWhereTheGridAloneLetsItSink) {
    for (const char* solver : {"fem_cst", "mpm"})
        for (const bool self : {false, true}) {
            const StackFigures f = droppedOnItself(solver, self);
            std::printf(
                "%s, contact.self = %d: upper piece %.4f m over the lower, closest pair "
                "%.4f m, %d upper particles below the lower's mean\n",
                solver, self, f.meanGap, f.closestPair, f.below);
            if (self) {
                EXPECT_EQ(f.below, 0) << solver;
                EXPECT_GT(f.meanGap, 0.005) << solver;
            }
        }
    const StackFigures grid = droppedOnItself("mpm", false);
    EXPECT_GT(grid.below, 0) << "the grid alone lets it sink (README \"Solvers\": keep contact)";
}
