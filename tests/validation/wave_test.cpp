// VALIDATION.md, "wave arrival, plane stress: c_p = sqrt(E / (rho (1 - nu^2))), within 2% for
// wavelength >= 10 delta".
//
// The left edge of a wide sheet is driven in x with a velocity that ramps linearly from 0 to v0
// over T_r = 10 delta / c_p and then stays at v0 (a smoothed step). In the middle of the sheet the
// front is a plane wave in uniaxial strain (the width keeps the lateral free edges out: their
// release waves reach the centre line at x only sqrt(x^2 + H^2)/c_p after the start, far behind
// the front). Behind a plane front the particle velocity equals the driving velocity, so the
// arrival at a probe line is when the mean x-velocity of its particles (|y| < 0.2 m) crosses
// v0 / 2, interpolated linearly between steps. The speed is the distance between two probe lines
// over the difference of their arrival times, which cancels the ramp's delay and the position of
// the driven edge. With the bond-based nu = 1/3, c_p = sqrt(9 E / (8 rho)).

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "sim/Membrane.h"

using namespace rend::sim;

TEST(ValidationWave, PlaneStressPWaveFrontTravelsAtCpWithinTwoPercent) {
    const double E = 2e4, rho = 5000, nu = 1.0 / 3.0, dx = 0.02, length = 2.2, width = 3.0;
    const double cp = std::sqrt(E / (rho * (1 - nu * nu)));
    const double delta = 1.5 * dx;
    const double ramp = 10 * delta / cp;  // wavelength of the front >= 10 delta
    const double v0 = 1e-3;               // strain v0 / c_p ~ 5e-4

    MembraneParams p;
    p.sheet.size = {length, width};
    p.sheet.dx = dx;
    p.material.youngsModulus = E;
    p.material.density = rho;
    p.time.integrator = Integrator::VelocityVerlet;
    BoundaryCondition drive;
    drive.kind = BoundaryKind::Velocity;
    drive.region.max.x() = -0.5 * length + 0.6 * dx;  // both zig-zag columns of the left edge
    drive.velocity = {v0, 0, 0};
    drive.rampTime = ramp;
    p.boundaries = {drive};
    Membrane m(p);

    const double left = -0.5 * length;
    const double probeX[2] = {left + 0.6, left + 1.5};  // lattice columns of the even rows
    std::vector<int> probe[2];
    for (int k = 0; k < 2; ++k)
        for (int i = 0; i < m.particleCount(); ++i) {
            const auto& x = m.restPositions()[i];
            if (std::abs(x.x() - probeX[k]) < 0.25 * dx && std::abs(x.y()) < 0.2)
                probe[k].push_back(i);
        }
    ASSERT_FALSE(probe[0].empty());
    ASSERT_FALSE(probe[1].empty());
    auto meanVx = [&](int k) {
        double sum = 0.0;
        for (int i : probe[k]) sum += m.velocities()[i].x();
        return sum / double(probe[k].size());
    };

    double arrival[2] = {-1, -1}, before[2] = {0, 0};
    const double tEnd = (probeX[1] - left) / cp + 2 * ramp;
    while (m.time() < tEnd && arrival[1] < 0) {
        const double t0 = m.time();
        m.step();
        for (int k = 0; k < 2; ++k) {
            const double v = meanVx(k);
            if (arrival[k] < 0 && v >= 0.5 * v0)
                arrival[k] = t0 + (m.time() - t0) * (0.5 * v0 - before[k]) / (v - before[k]);
            before[k] = v;
        }
    }
    ASSERT_GT(arrival[0], 0.0);
    ASSERT_GT(arrival[1], 0.0);
    const double speed = (probeX[1] - probeX[0]) / (arrival[1] - arrival[0]);
    const double error = speed / cp - 1.0;
    std::printf(
        "P wave: %d particles, dx = %.3g, ramp = 10 delta / c_p = %.4g s, probes %.2f m"
        " apart: arrivals %.5f s, %.5f s\n",
        m.particleCount(), dx, ramp, probeX[1] - probeX[0], arrival[0], arrival[1]);
    std::printf(
        "  measured speed %.5f m/s, c_p = sqrt(E/(rho(1-nu^2))) = %.5f m/s, error %+.3f%%"
        "  (target 2%%)\n",
        speed, cp, 100 * error);
    EXPECT_LT(std::abs(error), 0.02);
}
