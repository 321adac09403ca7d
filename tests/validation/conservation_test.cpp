// VALIDATION.md, "momentum / energy, no damping, no fracture: conserved; drift < 1e-3 over 1e5
// steps at 0.8 dt_crit (Verlet)", and momentum to 1e-12 relative.
//
// The run and which figure is the "drift" are explained in checks/Conservation.h.

#include "tests/validation/checks/Conservation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace rend::sim;
using namespace rend::checks;

TEST(ValidationConservation,
     VelocityVerletKeepsEnergyWithinOnePerMilleAndMomentumExactOver1e5Steps) {
    // Targets: energy drift < 1e-3 relative over 1e5 steps; momentum 1e-12 relative.
    const EnergyRun v = runFreeSheet({Integrator::VelocityVerlet, 0.8, 100000});
    std::printf("Verlet, %d particles, dt = %.4g s = 0.8 * %.4g s, 1e5 steps, no damping:\n",
                v.particles, v.dt, v.stableDt);
    std::printf("  energy drift (fitted slope over the run) = %+.3e  (target |drift| < 1e-3)\n",
                v.drift);
    std::printf("  constant offset <E>/E0 - 1 = %+.3e, max |E - E0|/E0 = %.3e (bounded, O(dt^2))\n",
                v.offset, v.worst);
    std::printf("  momentum |P - P0| / sum m|v| = %.3e  (target <= 1e-12)\n", v.momentum);
    EXPECT_LT(std::abs(v.drift), 1e-3);
    EXPECT_LE(v.momentum, 1e-12);

    const EnergyRun e = runFreeSheet({Integrator::SymplecticEuler, 0.8, 100000});
    std::printf(
        "symplectic Euler, same run: drift = %+.3e, offset = %+.3e, max |E - E0|/E0 ="
        " %.3e, momentum = %.3e\n",
        e.drift, e.offset, e.worst, e.momentum);
    EXPECT_LE(e.momentum, 1e-12);
    EXPECT_GT(e.worst, v.worst) << "Euler's energy error is the larger";

    // The offset is the time step's, not a drift: at half the step it falls about fourfold.
    const EnergyRun half = runFreeSheet({Integrator::VelocityVerlet, 0.4, 20000});
    std::printf(
        "Verlet at dt = 0.4 * bound, 2e4 steps: offset = %+.3e (%.1f times smaller),"
        " drift = %+.3e\n",
        half.offset, v.offset / half.offset, half.drift);
    EXPECT_GT(v.offset / half.offset, 3.0) << "O(dt^2)";
}
