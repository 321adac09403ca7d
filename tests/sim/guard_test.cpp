// The blow-up guard (sim/BlowUpGuard.h): an unstable step is stopped soon after the instability
// shows, a stable run with every energy source never trips it, and its limits and messages stay
// finite whatever the scene says.

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "sim/BlowUpGuard.h"
#include "sim/Membrane.h"

using namespace rend::sim;

namespace {

// The stretch scene (scenes/stretch.toml) on a smaller sheet: both side edges pulled apart at
// 0.15 m/s after a 0.5 s ramp.
MembraneParams pulledSheet() {
    MembraneParams p;
    p.sheet.size = {0.6, 0.6};
    p.sheet.dx = 0.02;
    p.sheet.perturbationAmplitude = 1e-4;
    p.sheet.perturbationSeed = 7;
    p.material.youngsModulus = 2e4;
    p.material.density = 5000;
    for (double side : {-1.0, 1.0}) {
        BoundaryCondition bc;
        bc.kind = BoundaryKind::Velocity;
        if (side < 0)
            bc.region.max.x() = -0.3 + p.sheet.dx;
        else
            bc.region.min.x() = 0.3 - p.sheet.dx;
        bc.velocity = {0.15 * side, 0.0, 0.0};
        bc.rampTime = 0.5;
        p.boundaries.push_back(bc);
    }
    p.time.duration = 5.0;
    return p;
}

// Largest speed after each step of `steps` steps of dt; stops early at a blow-up.
std::vector<double> speedHistory(Membrane& m, double dt, int steps) {
    m.setTimeStep(dt);
    std::vector<double> speeds;
    for (int s = 0; s < steps; ++s) {
        m.step();
        speeds.push_back(m.maxSpeed());
    }
    return speeds;
}

bool printsNonFinite(const std::string& message) {
    return message.find("inf") != std::string::npos || message.find("nan") != std::string::npos;
}

}  // namespace

TEST(BlowUpGuard, StopsAnUnstableStepBeforeTheSpeedGrowsTenfoldOverTheStableRun) {
    // 1.44 x the Silling-Askari bound is the stretch case (dt = 1/120 s against
    // 0.0058 s); half of it is stable, and two of its steps land on each unstable one.
    const MembraneParams p = pulledSheet();
    Membrane stable(p), unstable(p);
    const double dt = 1.44 * stable.stableTimeStep();
    const std::vector<double> reference = speedHistory(stable, 0.5 * dt, 2000);
    std::vector<double> speeds;
    long caughtAt = -1;
    try {
        unstable.setTimeStep(dt);
        for (int s = 0; s < 1000; ++s) {
            unstable.step();
            speeds.push_back(unstable.maxSpeed());
        }
    } catch (const NumericalBlowUp& e) {
        caughtAt = e.step;
        EXPECT_GE(e.particle, 0);
        EXPECT_LT(e.particle, unstable.particleCount());
        EXPECT_GT(e.suggestedDt, 0.0);
        EXPECT_LE(e.suggestedDt, stable.stableTimeStep());
        EXPECT_NE(std::string(e.what()).find("kinetic energy grew"), std::string::npos) << e.what();
        EXPECT_FALSE(printsNonFinite(e.what())) << e.what();
    }
    ASSERT_GT(caughtAt, 0) << "1000 unstable steps ran without the guard";
    double stableMax = 0.0, worstRatio = 0.0;
    for (std::size_t s = 0; s < speeds.size(); ++s) {
        stableMax = std::max(stableMax, reference[2 * s + 1]);
        worstRatio = std::max(worstRatio, speeds[s] / stableMax);
    }
    std::printf(
        "[guard] unstable step caught at step %ld; largest speed before it %.3g x the "
        "stable run's\n",
        caughtAt, worstRatio);
    EXPECT_LT(worstRatio, 10.0);
}

TEST(BlowUpGuard, AStableRunWithBoundariesGravityPressureAndExpansionNeverTrips) {
    MembraneParams p = pulledSheet();
    p.gravity = {0.0, 0.0, -9.81};
    p.pressure = 5.0;
    p.material.conductivity = 1e-3;
    p.material.expansion = 0.01;
    p.diffusion.spots.push_back({Eigen::Vector2d(0.0, 0.0), 0.1, 5.0});
    Membrane m(p);
    // The step at the bound itself (auto uses 0.8 of it): the measured kinetic energy is then
    // furthest from the true energy.
    EXPECT_NO_THROW(speedHistory(m, m.stableTimeStep(), 1500));
}

TEST(BlowUpGuard, EnergyFromNowhereStopsTheRunEvenWhenItGrowsSlowly) {
    // Kinetic energy pumped in by 1.21x per step (below kGrowth) with nothing driving the sheet:
    // the runaway rule catches it once it is 10x what the run can have put in.
    MembraneParams p = pulledSheet();
    p.boundaries.clear();
    Membrane m(p);
    m.setTimeStep(0.5 * m.stableTimeStep());
    m.velocities()[100] = {0.0, 0.0, 0.01};
    try {
        for (int s = 0; s < 200; ++s) {
            m.step();
            for (auto& v : m.velocities()) v *= 1.1;
        }
        FAIL() << "energy pumped in for 200 steps ran without the guard";
    } catch (const NumericalBlowUp& e) {
        EXPECT_NE(std::string(e.what()).find("the kinetic energy reached"), std::string::npos)
            << e.what();
        EXPECT_LT(m.maxSpeed(), 10.0);
    }
}

TEST(BlowUpGuard, LimitsAndMessagesStayFiniteForAbsurdGravity) {
    MembraneParams p = pulledSheet();
    p.gravity = {0.0, 0.0, -1e300};
    p.time.duration = 1e300;
    Membrane m(p);
    try {
        speedHistory(m, m.stableTimeStep() * 0.5, 10);
        FAIL() << "gravity of 1e300 m/s^2 ran without the guard";
    } catch (const NumericalBlowUp& e) {
        EXPECT_EQ(e.step, 1);
        EXPECT_GT(e.suggestedDt, 0.0);
        EXPECT_TRUE(std::isfinite(e.suggestedDt));
        EXPECT_FALSE(printsNonFinite(e.what())) << e.what();
        EXPECT_NE(std::string(e.what()).find("2.998e+08"), std::string::npos) << e.what();
    }
}

TEST(BlowUpGuard, SuggestsNoTimeStepWhenItWouldNotBeFinite) {
    EXPECT_DOUBLE_EQ(suggestedTimeStep(1e-3, 4e-3), 5e-4);
    EXPECT_DOUBLE_EQ(suggestedTimeStep(1e-3, std::numeric_limits<double>::infinity()), 5e-4);
    EXPECT_EQ(suggestedTimeStep(std::nan(""), 1e-3), 0.0);
    EXPECT_EQ(suggestedTimeStep(0.0, 1e-3), 0.0);
}

TEST(BlowUpGuard, SamplesGiveTheSameBitsForAnyThreadCount) {
    MembraneParams p = pulledSheet();
    p.sheet.size = {2.0, 2.0};  // above the parallel threshold
    Membrane m(p);
    speedHistory(m, 0.5 * m.stableTimeStep(), 50);
    BlowUpGuard guard(p, 1.0, m.masses(), m.volumes());
    std::vector<Eigen::Vector3d> force(m.particleCount(), Eigen::Vector3d::Ones());
    std::vector<std::int16_t> constraint(m.particleCount(), -1);
    constraint[0] = 0;
    const BlowUpGuard::State state{m.positions(), m.velocities(), force,     m.restPositions(),
                                   m.masses(),    m.theta(),      constraint};
    omp_set_num_threads(1);
    const BlowUpGuard::Sample one = guard.sample(state);
    omp_set_num_threads(4);
    const BlowUpGuard::Sample four = guard.sample(state);
    EXPECT_GT(one.kinetic, 0.0);
    EXPECT_EQ(one.kinetic, four.kinetic);
    EXPECT_EQ(one.boundaryPower, four.boundaryPower);
    EXPECT_EQ(one.fastest, four.fastest);
}

namespace {

bool sameBits(const BlowUpGuard::Sample& a, const BlowUpGuard::Sample& b) {
    return std::memcmp(&a.kinetic, &b.kinetic, 5 * sizeof(double)) == 0 && a.fastest == b.fastest &&
           a.firstBad == b.firstBad;
}

// The motion the integrator samples block by block as it moves them (Membrane::kickAndDrift)
// gives the sample check() takes in one pass, to the bit, with theta's part added at the check
// or handed over by the diffusion: a NaN theta is still found. Changed velocities after it are not
// seen once it is forgotten.
TEST(BlowUpGuard, TheMotionSampledAsItMovesIsTheCheckSample) {
    MembraneParams p = pulledSheet();
    p.sheet.size = {2.0, 2.0};  // several blocks
    Membrane m(p);
    speedHistory(m, 0.5 * m.stableTimeStep(), 20);
    BlowUpGuard guard(p, 1.0, m.masses(), m.volumes());
    const int n = m.particleCount();
    ASSERT_GT(n, 3 * BlowUpGuard::kBlock);
    std::vector<Eigen::Vector3d> force(n, Eigen::Vector3d::Ones()),
        v(m.velocities().begin(), m.velocities().end());
    std::vector<std::int16_t> constraint(n, -1);
    constraint[5] = 0, constraint[2000] = -2;
    std::vector<double> theta(n, 0.25);
    theta[1500] = -3.0, theta[2500] = std::numeric_limits<double>::quiet_NaN();
    const BlowUpGuard::State state{m.positions(), v,     force,     m.restPositions(),
                                   m.masses(),    theta, constraint};
    const BlowUpGuard::Sample once = guard.sample(state);
    EXPECT_EQ(once.firstBad, 2500);
    EXPECT_EQ(once.maxAbsTheta, 3.0);
    guard.beginMotion(0, n);
    for (int b = 0; b < (n + BlowUpGuard::kBlock - 1) / BlowUpGuard::kBlock; ++b)
        guard.sampleMotion(state, b);
    guard.endMotion();
    EXPECT_TRUE(sameBits(guard.sample(state), once));
    // theta's half handed over, as the diffusion takes it while it writes theta
    // (Diffusion::thetaSums): theta is not read for it, and the sample is the same.
    const GuardSums thetaSums = guardThetaSums(theta.data(), 0, n);
    BlowUpGuard::State handed = state;
    handed.thetaSums = &thetaSums;
    EXPECT_TRUE(sameBits(guard.sample(handed), once));
    std::vector<double> unread(n, 0.0);  // what sample() would see if it read theta
    handed.theta = unread;
    EXPECT_TRUE(sameBits(guard.sample(handed), once));
    v[7] *= 100.0;  // moved after the sampling: a stale sample unless forgotten
    const BlowUpGuard::Sample moved = guard.sample(state);
    EXPECT_TRUE(sameBits(moved, once));
    guard.forgetMotion();
    EXPECT_FALSE(sameBits(guard.sample(state), once));
}

}  // namespace
