#include "tests/validation/checks/Mpm.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "sim/Membrane.h"
#include "sim/Mpm.h"

namespace rend::checks {

using namespace sim;

namespace {

/// The probe line's particles: rest x within a quarter spacing of `at`, |y| < 0.2 m.
std::vector<int> probeLine(const Membrane& m, double at, double dx) {
    std::vector<int> line;
    for (int i = 0; i < m.particleCount(); ++i) {
        const Eigen::Vector3d& x = m.restPositions()[i];
        if (std::abs(x.x() - at) < 0.25 * dx && std::abs(x.y()) < 0.2) line.push_back(i);
    }
    if (line.empty()) throw std::logic_error("a probe line holds no particle");
    return line;
}

double meanVx(const Membrane& m, const std::vector<int>& line) {
    double sum = 0.0;
    for (const int i : line) sum += m.velocities()[i].x();
    return sum / double(line.size());
}

}  // namespace

WaveFigures planeWave(const std::string& solver, double dx, double nu, const MpmParams& mpm) {
    const double E = 2e4, rho = 5000, length = 2.2, width = 3.0;
    const double cp = std::sqrt(E / (rho * (1 - nu * nu)));
    const double ramp = 10 * 1.5 * dx / cp;  // wavelength of the front >= 10 delta
    const double v0 = 1e-3;
    MembraneParams p;
    p.solver = solver;
    p.mpm = mpm;
    p.sheet.size = {length, width};
    p.sheet.dx = dx;
    p.material.youngsModulus = E;
    p.material.poissonRatio = nu;
    p.material.density = rho;
    BoundaryCondition drive;
    drive.kind = BoundaryKind::Velocity;
    drive.region.max.x() = -0.5 * length + 0.6 * dx;  // both zig-zag columns of the left edge
    drive.velocity = {v0, 0, 0};
    drive.rampTime = ramp;
    p.boundaries = {drive};
    Membrane m(p);
    const double left = -0.5 * length, probeX[2] = {left + 0.6, left + 1.5};
    const std::vector<int> probe[2] = {probeLine(m, probeX[0], dx), probeLine(m, probeX[1], dx)};
    double arrival[2] = {-1, -1}, before[2] = {0, 0};
    const double tEnd = (probeX[1] - left) / cp + 2 * ramp;
    while (m.time() < 2 * tEnd && arrival[1] < 0) {
        const double t0 = m.time();
        m.step();
        for (int k = 0; k < 2; ++k) {
            const double v = meanVx(m, probe[k]);
            if (arrival[k] < 0 && v >= 0.5 * v0)
                arrival[k] = t0 + (m.time() - t0) * (0.5 * v0 - before[k]) / (v - before[k]);
            before[k] = v;
        }
    }
    if (arrival[1] < 0) return {0.0, m.particleCount()};
    return {(probeX[1] - probeX[0]) / (arrival[1] - arrival[0]) / cp, m.particleCount()};
}

namespace {

MembraneParams bimaterialPull(const std::string& solver, double dx, const MpmParams& mpm,
                              bool jerk) {
    MembraneParams p;
    p.solver = solver;
    p.mpm = mpm;
    p.sheet.size = {1.6, 0.3};
    p.sheet.dx = dx;
    p.material.youngsModulus = 2e4;
    p.material.density = 1000;
    MaterialMap soft;
    soft.property = MappedProperty::YoungsModulus;
    soft.min = {0.0, -1.0};
    soft.max = {1.0, 1.0};
    soft.factor = 0.25;
    p.materialMaps = {soft};
    BoundaryCondition pin, pull;
    pin.region.max.x() = -0.8 + 0.5 * dx;
    pull.kind = BoundaryKind::Velocity;
    pull.region.min.x() = 0.8 - 0.5 * dx;
    pull.velocity = {0.04, 0, 0};
    pull.rampTime = jerk ? 0.05 : 1.0;
    p.boundaries = {pin, pull};
    p.damping = jerk ? 0.0 : 4.0;
    return p;
}

/// The mean strain along x of the particles of the middle half of [from, to] (rest x).
double meanStrain(const Membrane& m, double from, double to) {
    const double a = from + 0.25 * (to - from), b = to - 0.25 * (to - from);
    double sx = 0, su = 0, sxx = 0, sxu = 0, n = 0;
    for (int i = 0; i < m.particleCount(); ++i) {
        const double x = m.restPositions()[i].x();
        if (x < a || x > b) continue;
        const double u = m.positions()[i].x() - x;
        sx += x, su += u, sxx += x * x, sxu += x * u, n += 1;
    }
    return (n * sxu - sx * su) / (n * sxx - sx * sx);
}

}  // namespace

namespace {

PullFigures compared(MembraneParams p, double until) {
    Membrane m(p);
    p.solver = "fem_cst";
    Membrane fem(p);
    m.advanceTo(until);
    fem.advanceTo(until);
    double worst = 0.0, largest = 0.0;
    for (int i = 0; i < m.particleCount(); ++i) {
        const Eigen::Vector3d u = m.positions()[i] - m.restPositions()[i];
        const Eigen::Vector3d uFem = fem.positions()[i] - fem.restPositions()[i];
        worst = std::max(worst, (u - uFem).norm());
        largest = std::max(largest, uFem.norm());
    }
    const auto* mpmSolver = dynamic_cast<const Mpm*>(&m.solver());
    return {worst / largest, meanStrain(m, 0.0, 0.8) / meanStrain(m, -0.8, 0.0),
            mpmSolver ? mpmSolver->enrichedCount() : 0, m.particleCount()};
}

}  // namespace

PullFigures pulledBimaterial(const std::string& solver, double dx, const MpmParams& mpm,
                             bool jerk) {
    return compared(bimaterialPull(solver, dx, mpm, jerk), jerk ? 1.0 : 5.0);
}

PullFigures pulledStripes(double dx, double stripe, const MpmParams& mpm) {
    MembraneParams p = bimaterialPull("mpm", dx, mpm, true);
    p.materialMaps.clear();
    for (double x = -0.8; x < 0.8; x += 2 * stripe) {
        MaterialMap soft;
        soft.property = MappedProperty::YoungsModulus;
        soft.min = {x, -1.0};
        soft.max = {x + stripe, 1.0};
        soft.factor = 0.1;
        p.materialMaps.push_back(soft);
    }
    return compared(p, 1.0);
}

namespace {

double angularMomentumZ(const Membrane& m) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    double mass = 0.0;
    for (int i = 0; i < m.particleCount(); ++i) {
        centre += m.masses()[i] * m.positions()[i];
        mass += m.masses()[i];
    }
    centre /= mass;
    double L = 0.0;
    for (int i = 0; i < m.particleCount(); ++i)
        L += m.masses()[i] * (m.positions()[i] - centre).cross(m.velocities()[i]).z();
    // APIC's particles also carry the spin of their affine field C_p over their own extent,
    // the inertia D_p = h^2 / 4 I of the quadratic spline: m (tr D - D) w, w_z = (C_yx - C_xy) / 2.
    if (const auto* mpm = dynamic_cast<const Mpm*>(&m.solver())) {
        const double h = mpm->grid().spacing();
        for (int i = 0; i < m.particleCount(); ++i) {
            const Eigen::Matrix3d& C = mpm->affine()[i];
            L += m.masses()[i] * h * h / 4 * (C(1, 0) - C(0, 1));
        }
    }
    return L;
}

}  // namespace

SpinFigures spinningSheet(const std::string& solver, int steps, const MpmParams& mpm, bool disc,
                          int remeshEvery) {
    MembraneParams p;
    p.solver = solver;
    p.mpm = mpm;
    p.remesh.every = remeshEvery;
    p.sheet.size = {0.4, 0.4};
    if (disc) p.sheet.outline = Outline::Disc, p.sheet.radius = 0.2;
    p.sheet.dx = 0.02;
    p.material.youngsModulus = 2e4;
    p.material.density = 5000;
    Membrane probe(p);
    p.time.dt = 0.5 * probe.stableTimeStep();
    Membrane m(p);
    const double spin = disc ? std::sqrt(10.0) : 1.0;  // rho w^2 R^2 / E about 10% or 1%
    for (int i = 0; i < m.particleCount(); ++i)
        m.velocities()[i] = spin * Eigen::Vector3d::UnitZ().cross(m.positions()[i]);
    const double L0 = angularMomentumZ(m), ke0 = m.kineticEnergy();
    for (int k = 0; k < steps; ++k) m.step();
    return {std::abs(angularMomentumZ(m) - L0) / std::abs(L0), m.kineticEnergy() / ke0};
}

namespace {

double closestUnbondedPair(const Membrane& m) {
    const auto& x = m.positions();
    const auto& rest = m.restPositions();
    const double reach2 = std::pow(m.horizon() * (1 + 1e-9), 2);
    double closest = 1e300;
    for (int i = 0; i < m.particleCount(); ++i)
        for (int j = i + 1; j < m.particleCount(); ++j)
            if ((rest[i] - rest[j]).squaredNorm() > reach2)
                closest = std::min(closest, (x[i] - x[j]).norm());
    return closest;
}

}  // namespace

StackFigures droppedOnItself(const std::string& solver, bool selfContact, const MpmParams& mpm) {
    const double width = 0.2, dx = 0.02, cut = 0.3 * dx;
    MembraneParams p;
    p.solver = solver;
    p.sheet.size = {width, 2 * width};
    p.sheet.dx = dx;
    p.material.youngsModulus = 2e4;
    p.material.density = 5000;
    p.gravity = {0, 0, -9.81};
    p.contact.ground.enabled = true;
    p.contact.self.enabled = selfContact;
    p.mpm = mpm;
    p.sheet.center.z() = 0.25 * dx;
    p.notches.push_back(Notch{{{-width, cut}, {width, cut}}});
    p.damping = 2.0;
    Membrane m(p);
    for (int i = 0; i < m.particleCount(); ++i)
        if (m.restPositions()[i].y() > cut) m.positions()[i] += Eigen::Vector3d(0, -width, 0.04);
    const auto start = std::chrono::steady_clock::now();
    double closest = 1e300;
    for (int frame = 1; frame <= 40; ++frame) {
        m.advanceTo(frame * 0.02);
        closest = std::min(closest, closestUnbondedPair(m));
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    double upper = 0, lower = 0;
    int nu = 0, nl = 0;
    for (int i = 0; i < m.particleCount(); ++i) {
        const bool top = m.restPositions()[i].y() > cut;
        (top ? upper : lower) += m.positions()[i].z();
        (top ? nu : nl) += 1;
    }
    int below = 0;
    for (int i = 0; i < m.particleCount(); ++i)
        if (m.restPositions()[i].y() > cut && m.positions()[i].z() < lower / nl) ++below;
    return {upper / nu - lower / nl, closest, seconds, below};
}

}  // namespace rend::checks
