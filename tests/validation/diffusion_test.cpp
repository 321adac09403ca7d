// VALIDATION.md, "1D / 2D diffusion: erfc profile; Gaussian spreading of a point source: L2 error
// < 2%, decreasing under refinement; insulated domain conserves total to 1e-12".
//
// Eq. 25 is calibrated so the interior solves rho C dtheta/dt = k laplacian(theta), i.e.
// D = k / (rho C). Expansion is 0, so the sheet never moves and only theta evolves; the mechanical
// step is set large and Diffusion::advance sub-steps it at 0.9 of its forward-Euler bound.
// L2 error = sqrt(sum (theta - theta_ref)^2 / sum theta_ref^2) over the particles named below.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "sim/Membrane.h"

using namespace rend::sim;

namespace {

constexpr double kConductivity = 50.0, kDensity = 5000.0, kCapacity = 1.0;
constexpr double kD = kConductivity / (kDensity * kCapacity);  // 0.01 m^2/s

MembraneParams diffusingSheet(double sx, double sy, double dx) {
    MembraneParams p;
    p.sheet.size = {sx, sy};
    p.sheet.dx = dx;
    p.material.density = kDensity;
    p.material.capacity = kCapacity;
    p.material.conductivity = kConductivity;
    p.material.expansion = 0.0;
    return p;
}

void runFor(Membrane& m, double duration, int steps) {
    m.setTimeStep(duration / steps);
    for (int s = 0; s < steps; ++s) m.step();
}

struct StripResult {
    double l2Centre, l2All, l2NaiveEdge;
};

// Semi-infinite strip with theta = 1 held on the left edge: theta = erfc(x / (2 sqrt(D t))).
// Where the held edge acts: the left edge of the hexagonal lattice is a zig-zag, both columns
// (x_l and x_l + dx/2) are held. For a profile that depends on x only, the lattice projects onto
// a chain of spacing s = dx/2 with couplings r to +-2s and 2r to +-s (equal W0 and |xi| for all
// six neighbours). Its homogeneous solutions are 1, n and lambda^n with lambda + 1/lambda = -4,
// lambda = sqrt(3) - 2; fitting theta_0 = theta_1 = held gives the far field of a Dirichlet edge
// at x_b = x_l + s / (1 - lambda) = x_l + dx / (2 (3 - sqrt(3))) = x_l + 0.394 dx. The naive
// mid-point x_l + dx/4 is printed for comparison.
StripResult heldEdgeStrip(double dx) {
    const double length = 1.0, height = 0.4, duration = 1.0;  // 2 sqrt(D t) = 0.2 m
    MembraneParams p = diffusingSheet(length, height, dx);
    DiffusionEdge edge;
    edge.region.max.x() = -0.5 * length + 0.6 * dx;
    edge.value = 1.0;
    p.diffusion.edges = {edge};
    Membrane m(p);
    runFor(m, duration, 20);
    const double xl = -0.5 * length;
    const double xb = xl + dx / (2 * (3 - std::sqrt(3.0)));
    const double xNaive = xl + 0.25 * dx;
    const double scale = 2 * std::sqrt(kD * m.time());
    double errC = 0, refC = 0, errA = 0, refA = 0, errN = 0, refN = 0;
    for (int i = 0; i < m.particleCount(); ++i) {
        const Eigen::Vector3d& x = m.restPositions()[i];
        if (edge.region.contains(x)) continue;
        const double ref = std::erfc((x.x() - xb) / scale);
        const double naive = std::erfc((x.x() - xNaive) / scale);
        const double th = m.theta()[i];
        errA += (th - ref) * (th - ref), refA += ref * ref;
        errN += (th - naive) * (th - naive), refN += naive * naive;
        if (std::abs(x.y()) <= 0.25 * height) errC += (th - ref) * (th - ref), refC += ref * ref;
    }
    return {std::sqrt(errC / refC), std::sqrt(errA / refA), std::sqrt(errN / refN)};
}

struct GaussResult {
    double l2, varianceX, varianceY, varianceRef, conservation;
    int particles;
};

// Gaussian of variance s0^2 per axis: theta = s0^2 / s^2 exp(-r^2 / (2 s^2)), s^2 = s0^2 + 2 D t.
GaussResult spreadingGaussian(double dx) {
    const double half = 0.6, s0 = 0.08, duration = 0.32;  // s^2 = 2 s0^2
    MembraneParams p = diffusingSheet(2 * half, 2 * half, dx);
    p.diffusion.initial = 1e-300;  // switches theta on; overwritten below
    Membrane m(p);
    auto moments = [&](double& total, double& vx, double& vy) {
        total = vx = vy = 0.0;
        for (int i = 0; i < m.particleCount(); ++i) total += m.theta()[i];
        Eigen::Vector2d c = Eigen::Vector2d::Zero();
        for (int i = 0; i < m.particleCount(); ++i)
            c += m.theta()[i] * m.restPositions()[i].head<2>() / total;
        for (int i = 0; i < m.particleCount(); ++i) {
            const Eigen::Vector2d d = m.restPositions()[i].head<2>() - c;
            vx += m.theta()[i] * d.x() * d.x() / total;
            vy += m.theta()[i] * d.y() * d.y() / total;
        }
    };
    for (int i = 0; i < m.particleCount(); ++i)
        m.theta()[i] = std::exp(-m.restPositions()[i].head<2>().squaredNorm() / (2 * s0 * s0));
    double total0, vx0, vy0;
    moments(total0, vx0, vy0);
    runFor(m, duration, 16);
    double total, vx, vy;
    moments(total, vx, vy);
    const double s2 = s0 * s0 + 2 * kD * m.time();
    double err = 0, ref = 0;
    for (int i = 0; i < m.particleCount(); ++i) {
        const double r2 = m.restPositions()[i].head<2>().squaredNorm();
        const double exact = s0 * s0 / s2 * std::exp(-r2 / (2 * s2));
        err += (m.theta()[i] - exact) * (m.theta()[i] - exact);
        ref += exact * exact;
    }
    // The discrete initial variance (vx0, vy0) plus 2 D t is what the spread must reach.
    return {std::sqrt(err / ref),           vx - vx0,         vy - vy0, 2 * kD * m.time(),
            std::abs(total / total0 - 1.0), m.particleCount()};
}

}  // namespace

TEST(ValidationDiffusion, HeldEdgeGivesTheErfcProfileWithinTwoPercentAndConvergesUnderRefinement) {
    // Target: L2 < 2%, decreasing from dx to dx/2 at the same horizon factor (VALIDATION.md).
    const StripResult coarse = heldEdgeStrip(0.02);
    const StripResult fine = heldEdgeStrip(0.01);
    for (const auto& [dx, r] : {std::pair{0.02, coarse}, std::pair{0.01, fine}})
        std::printf(
            "1D erfc, dx = %.3f: L2 over |y| <= H/4 = %.3e, over all free particles ="
            " %.3e (edge at x_l + 0.394 dx); with the naive edge x_l + dx/4: %.3e"
            "  (target 2%%)\n",
            dx, r.l2Centre, r.l2All, r.l2NaiveEdge);
    EXPECT_LT(coarse.l2Centre, 0.02);
    EXPECT_LT(fine.l2Centre, 0.02);
    EXPECT_LT(fine.l2Centre, coarse.l2Centre) << "decreasing under refinement";
}

TEST(ValidationDiffusion, GaussianSpreadsWithVarianceTwoDtWithinTwoPercentAndConservesItsTotal) {
    // Targets: L2 < 2%, decreasing under refinement; insulated total to 1e-12 (VALIDATION.md).
    const GaussResult coarse = spreadingGaussian(0.02);
    const GaussResult fine = spreadingGaussian(0.01);
    for (const auto& [dx, r] : {std::pair{0.02, coarse}, std::pair{0.01, fine}})
        std::printf(
            "2D Gaussian, dx = %.3f (%d particles): L2 = %.3e (target 2%%); variance gain"
            " x %.6e, y %.6e vs 2Dt = %.6e; |total/total0 - 1| = %.1e (target 1e-12)\n",
            dx, r.particles, r.l2, r.varianceX, r.varianceY, r.varianceRef, r.conservation);
    EXPECT_LT(coarse.l2, 0.02);
    EXPECT_LT(fine.l2, 0.02);
    EXPECT_LT(fine.l2, coarse.l2) << "decreasing under refinement";
    EXPECT_LE(coarse.conservation, 1e-12);
    EXPECT_LE(fine.conservation, 1e-12);
}
