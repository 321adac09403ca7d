#include "tests/validation/checks/Conservation.h"

#include <algorithm>
#include <cmath>

#include "sim/Membrane.h"
#include "sim/Random.h"

namespace rend::checks {

using namespace rend::sim;

namespace {

MembraneParams sheetParams(Integrator integrator) {
    MembraneParams p;
    p.sheet.size = {0.4, 0.4};
    p.sheet.dx = 0.02;
    p.material.youngsModulus = 2e4;
    p.material.density = 5000;
    p.time.integrator = integrator;
    p.time.duration = 1e9;  // only feeds the blow-up guard's speed limit
    return p;
}

/// Seeded velocities, 0.01 m/s in x, y and z (the wave speed is ~2 m/s), mean removed; returns
/// sum m |v|, the scale momentum errors are measured against.
double kick(Membrane& m) {
    const int n = m.particleCount();
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
    return scale;
}

}  // namespace

EnergyRun runFreeSheet(const FreeSheet& s) {
    Membrane m(sheetParams(s.integrator));
    m.setTimeStep(s.safety * m.stableTimeStep());
    const double scale = kick(m);
    const Eigen::Vector3d p0 = m.totalMomentum();
    const double e0 = m.kineticEnergy() + m.strainEnergy();
    double worst = 0.0, st = 0.0, sy = 0.0, stt = 0.0, sty = 0.0;
    long count = 0;
    for (long k = 1; k <= s.steps; ++k) {
        m.step();
        if (k % s.every != 0) continue;
        const double e = (m.kineticEnergy() + m.strainEnergy()) / e0 - 1.0;
        worst = std::max(worst, std::abs(e));
        if (k <= s.settle) continue;
        const double t = double(k) / double(s.steps);  // the slope is then per run
        st += t, sy += e, stt += t * t, sty += t * e, ++count;
    }
    const double slope = (count * sty - st * sy) / (count * stt - st * st);
    return {slope,
            sy / count,
            worst,
            (m.totalMomentum() - p0).norm() / scale,
            m.particleCount(),
            m.timeStep(),
            m.stableTimeStep()};
}

double freeSheetStableStep() {
    return Membrane(sheetParams(Integrator::VelocityVerlet)).stableTimeStep();
}

}  // namespace rend::checks
