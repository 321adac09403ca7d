// VALIDATION.md, "Griffith centre crack, half length a >= 10 delta: sigma_c = sqrt(E G_f / (pi a)),
// within 15%". A plate 6a wide and 4a high with a centre notch of half-length a, perpendicular to
// the load, is pulled slowly at its top and bottom rows (quasi-static: a ramp over two transits
// of the height, then ten more to reach sigma_c, light damping). The far-field stress at the step
// the crack first grows beyond the notch is the mean virial sigma_yy of full-width bands of rows
// between the crack and the grips (a full section carries the whole load, so its mean is the
// gross stress), checked against the grips' reaction force.
//
// The plate is finite: Feddersen's width correction sqrt(cos(pi a / W)) lowers the expected
// gross stress by 7% at W = 6a; it is printed, the target is against the plain Griffith value.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "sim/Membrane.h"

using namespace rend::sim;

namespace {

constexpr double kE = 2e4;         // Pa
constexpr double kDensity = 5000;  // kg/m^3
constexpr double kThickness = 1e-3;
constexpr double kFractureEnergy = 0.25;  // J/m^2

struct Onset {
    double bandStress = 0.0;      ///< mean sigma_yy of the far-field bands [Pa]
    double reactionStress = 0.0;  ///< grip reaction / (W h) [Pa]
    double kineticShare = 0.0;    ///< kinetic / strain energy at onset
    double seconds = 0.0;
    long steps = 0;
    int particles = 0;
    bool grew = false;
};

/// Centre crack of half-length `halfLength` = `horizons` * R on a plate 10a x 6a at R = 1.5 dx.
Onset pullCentreCrack(double horizons, double dx, double factor, double widthOverA,
                      double heightOverA, double transits) {
    const double a = horizons * factor * dx;
    const double width = widthOverA * a, height = heightOverA * a;
    MembraneParams p;
    p.sheet.size = {width, height};
    p.sheet.dx = dx;
    p.sheet.horizonFactor = factor;
    p.sheet.thickness = kThickness;
    p.material.youngsModulus = kE;
    p.material.density = kDensity;
    p.material.fractureEnergy = kFractureEnergy;
    double below = -1e9, above = 1e9;  // the notch lies halfway between the rows next to y = 0
    double top = 0.0;                  // the top row
    const Membrane probe(p);
    for (const auto& x : probe.restPositions()) {
        if (x.y() <= 0.0) below = std::max(below, x.y());
        if (x.y() > 0.0) above = std::min(above, x.y());
        top = std::max(top, x.y());
    }
    const double y = 0.5 * (below + above);
    p.notches = {Notch{{{-a, y}, {a, y}}}};
    // Griffith's strain sqrt(G_f / (pi E a)) reached after ~20 transits of the height.
    const double waveSpeed = std::sqrt(kE / (kDensity * (1.0 - 1.0 / 9.0)));
    const double rampTime = 2.0 * height / waveSpeed;
    const double loadTime = transits * height / waveSpeed;
    const double strainC = std::sqrt(kFractureEnergy / (std::numbers::pi * kE * a));
    const double speed = 0.5 * strainC * height / loadTime;
    BoundaryCondition upper, lower;  // the top and bottom rows (the lattice is symmetric)
    upper.kind = lower.kind = BoundaryKind::Velocity;
    upper.region.min.y() = top - 0.25 * dx;
    lower.region.max.y() = -top + 0.25 * dx;
    upper.velocity = {0, speed, 0};
    lower.velocity = {0, -speed, 0};
    upper.rampTime = lower.rampTime = rampTime;
    p.boundaries = {upper, lower};
    p.damping = 0.5;  // 1/s
    Membrane m(p);

    std::vector<int> band, grip;  // full-width rows between the crack and the grips; the top grip
    for (int i = 0; i < m.particleCount(); ++i) {
        const Eigen::Vector3d& x = m.restPositions()[i];
        if (std::abs(x.y()) >= 0.3 * height && std::abs(x.y()) <= 0.4 * height) band.push_back(i);
        if (upper.region.contains(x)) grip.push_back(i);
    }
    Onset o;
    o.particles = m.particleCount();
    const std::size_t notched = m.notchedBondCount();
    const long maxSteps = long(3.0 * (rampTime + loadTime) / m.timeStep());
    for (long s = 0; s < maxSteps; ++s) {
        m.step();
        if (m.brokenBondCount() == notched) continue;
        o.grew = true;
        o.seconds = m.time();
        o.steps = m.stepCount();
        for (int i : band) o.bandStress += m.particleStress(i)(1, 1);
        o.bandStress /= double(band.size());
        std::vector<Eigen::Vector3d> f;
        m.computeForces(f);
        double reaction = 0.0;  // the sheet pulls the top grip down
        for (int i : grip) reaction -= f[i].y();
        o.reactionStress = reaction / (width * kThickness);
        o.kineticShare = m.kineticEnergy() / m.strainEnergy();
        break;
    }
    return o;
}

}  // namespace

TEST(Griffith, CentreCrackGrowsAtTheGriffithStress) {
    // Reference: VALIDATION.md "Griffith centre crack", sigma_c = sqrt(E G_f / (pi a)) for
    // a >= 10 delta; target within 15%, checked at R = 3 dx. At the paper's R = 1.5 dx (one ring
    // of neighbours: a lattice, not a continuum) the notch tip is trapped until 1.77 x sigma_c
    // (3.1 G_f) whatever a / delta is (also 1.79 at a = 20 delta); printed, not checked.
    struct Case {
        double horizons, dx, factor, width, height, transits;
        bool checked;
    };
    for (const Case& k :
         {Case{10.0, 0.01, 1.5, 6, 4, 10, false}, Case{10.0, 0.01, 3.0, 6, 4, 10, true}}) {
        const auto t0 = std::chrono::steady_clock::now();
        const Onset o = pullCentreCrack(k.horizons, k.dx, k.factor, k.width, k.height, k.transits);
        const double wall =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        ASSERT_TRUE(o.grew) << "the crack never grew";
        const double a = k.horizons * k.factor * k.dx;
        const double griffith = std::sqrt(kE * kFractureEnergy / (std::numbers::pi * a));
        const double feddersen = griffith * std::sqrt(std::cos(std::numbers::pi / k.width));
        std::printf(
            "[griffith] R = %.1f dx, a = %.0f delta, plate %.0fa x %.0fa (%d particles, %.1f s): "
            "crack grows at t = %.3f s (step %ld); "
            "far-field sigma_yy = %.3f Pa (reaction %.3f Pa, kinetic/strain energy %.2e); "
            "Griffith %.3f Pa -> %.4f (error %+.1f%%); with the width correction "
            "%.3f Pa -> %.4f\n",
            k.factor, k.horizons, k.width, k.height, o.particles, wall, o.seconds, o.steps,
            o.bandStress, o.reactionStress, o.kineticShare, griffith, o.bandStress / griffith,
            100.0 * (o.bandStress / griffith - 1.0), feddersen, o.bandStress / feddersen);
        EXPECT_NEAR(o.reactionStress / o.bandStress, 1.0, 0.03) << "quasi-static: one stress";
        if (k.checked) {
            EXPECT_NEAR(o.bandStress / griffith, 1.0, 0.15);
        }
    }
}
