// VALIDATION.md, "momentum / energy, no damping, no fracture: conserved; drift < 1e-3 over 1e5
// steps at 0.8 dt_crit (Verlet)", and momentum to 1e-12 relative.
//
// A free sheet of ~500 particles (no boundaries, no damping, no fracture, no gravity) starts at
// rest shape with seeded random velocities in all three directions, of zero mean, and runs 1e5
// steps at dt = 0.8 * stableTimeStep(). Total energy is kineticEnergy() + strainEnergy().
//
// Which figure is the "drift": with random velocities every lattice mode is excited, and at
// 0.8 of the Silling-Askari bound the highest in-plane mode has omega dt = 0.8 * sqrt(2) = 1.13
// (the bound is the Gershgorin estimate, 1/sqrt(2) of the true limit 2/omega_max on the
// hexagonal lattice). A symplectic scheme conserves a modified energy H + O(dt^2): the energy
// settles within a few hundred steps at a constant offset from E0 (the start, at rest shape, is not
// a typical point of the orbit) and oscillates about it with no secular growth. So the drift is the
// least-squares slope of E(t)/E0 over steps 1001..1e5, times the length of the run; the offset and
// the largest |E - E0|/E0 are printed beside it, and are what separates the two integrators.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "sim/Membrane.h"
#include "sim/Random.h"

using namespace rend::sim;

namespace {

struct EnergyRun {
    double drift;     ///< fitted slope of E/E0 over steps 1001..end, times the run's steps
    double offset;    ///< mean of E/E0 - 1 over steps 1001..end
    double worst;     ///< max over samples of |E - E0| / E0
    double momentum;  ///< |P(end) - P(0)| / sum m |v| at the start
    int particles;
    double dt, stableDt;
};

EnergyRun runFreeSheet(Integrator integrator, long steps, double safety = 0.8) {
    MembraneParams p;
    p.sheet.size = {0.4, 0.4};
    p.sheet.dx = 0.02;
    p.material.youngsModulus = 2e4;
    p.material.density = 5000;
    p.time.integrator = integrator;
    p.time.duration = 1e9;  // only feeds the blow-up guard's speed limit
    Membrane m(p);
    m.setTimeStep(safety * m.stableTimeStep());
    const int n = m.particleCount();
    // Seeded velocities, 0.01 m/s in x, y and z (the wave speed is ~2 m/s), mean removed.
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k)
            m.velocities()[i][k] = 0.01 * (2 * uniformFromHash(7, 3 * std::uint64_t(i) + k) - 1);
        mean += m.velocities()[i];
    }
    mean /= n;  // equal masses
    double scale = 0.0;
    for (int i = 0; i < n; ++i) {
        m.velocities()[i] -= mean;
        scale += m.masses()[i] * m.velocities()[i].norm();
    }
    const Eigen::Vector3d p0 = m.totalMomentum();
    const double e0 = m.kineticEnergy() + m.strainEnergy();
    const long settle = 1000, every = 10;
    double worst = 0.0, st = 0.0, sy = 0.0, stt = 0.0, sty = 0.0;
    long count = 0;
    for (long s = 1; s <= steps; ++s) {
        m.step();
        if (s % every != 0) continue;
        const double e = (m.kineticEnergy() + m.strainEnergy()) / e0 - 1.0;
        worst = std::max(worst, std::abs(e));
        if (s <= settle) continue;
        const double t = double(s) / double(steps);  // the slope is then per run
        st += t, sy += e, stt += t * t, sty += t * e, ++count;
    }
    const double slope = (count * sty - st * sy) / (count * stt - st * st);
    return {slope,        sy / count,        worst, (m.totalMomentum() - p0).norm() / scale, n,
            m.timeStep(), m.stableTimeStep()};
}

}  // namespace

TEST(ValidationConservation,
     VelocityVerletKeepsEnergyWithinOnePerMilleAndMomentumExactOver1e5Steps) {
    // Targets: energy drift < 1e-3 relative over 1e5 steps; momentum 1e-12 relative.
    const EnergyRun v = runFreeSheet(Integrator::VelocityVerlet, 100000);
    std::printf("Verlet, %d particles, dt = %.4g s = 0.8 * %.4g s, 1e5 steps, no damping:\n",
                v.particles, v.dt, v.stableDt);
    std::printf("  energy drift (fitted slope over the run) = %+.3e  (target |drift| < 1e-3)\n",
                v.drift);
    std::printf("  constant offset <E>/E0 - 1 = %+.3e, max |E - E0|/E0 = %.3e (bounded, O(dt^2))\n",
                v.offset, v.worst);
    std::printf("  momentum |P - P0| / sum m|v| = %.3e  (target <= 1e-12)\n", v.momentum);
    EXPECT_LT(std::abs(v.drift), 1e-3);
    EXPECT_LE(v.momentum, 1e-12);

    const EnergyRun e = runFreeSheet(Integrator::SymplecticEuler, 100000);
    std::printf(
        "symplectic Euler, same run: drift = %+.3e, offset = %+.3e, max |E - E0|/E0 ="
        " %.3e, momentum = %.3e\n",
        e.drift, e.offset, e.worst, e.momentum);
    EXPECT_LE(e.momentum, 1e-12);
    EXPECT_GT(e.worst, v.worst) << "Euler's energy error is the larger";

    // The offset is the time step's, not a drift: at half the step it falls about fourfold.
    const EnergyRun half = runFreeSheet(Integrator::VelocityVerlet, 20000, 0.4);
    std::printf(
        "Verlet at dt = 0.4 * bound, 2e4 steps: offset = %+.3e (%.1f times smaller),"
        " drift = %+.3e\n",
        half.offset, v.offset / half.offset, half.drift);
    EXPECT_GT(v.offset / half.offset, 3.0) << "O(dt^2)";
}
