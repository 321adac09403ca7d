// The adaptive time step (sim/TimeStep.h): its controller alone, and driven by a Membrane.

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <tuple>

#include "sim/Membrane.h"
#include "sim/TimeStep.h"

namespace rend::sim {
namespace {

/// A 1 m notched sheet (2.9K particles, over the parallel threshold) pulled apart at its top and
/// bottom edges: the crack runs from the notch within half a second.
MembraneParams tearingSheet() {
    MembraneParams p;
    p.sheet.size = {1.0, 1.0};
    p.sheet.dx = 0.02;
    p.material.youngsModulus = 2e4;
    p.material.density = 5000;
    p.material.fractureEnergy = 1.0;
    p.notches = {Notch{{{-0.55, 0.001}, {-0.2, 0.001}}}};
    BoundaryCondition top, bottom;
    top.kind = bottom.kind = BoundaryKind::Velocity;
    top.region.min.y() = 0.48;
    bottom.region.max.y() = -0.48;
    top.velocity = {0, 0.3, 0};
    bottom.velocity = {0, -0.3, 0.01};
    p.boundaries = {top, bottom};
    return p;
}

TEST(TimeStepController, TakesHalfTheBoundOrTheLowerSafetyWhenNothingLimitsIt) {
    TimeParams t;  // safety 0.8, auto's
    TimeStepController c(t);
    EXPECT_DOUBLE_EQ(c.next(1.0), TimeStepController::kMostOfBound);
    EXPECT_EQ(c.lastLimit(), StepLimit::Bound);
    c.record(0.5, 0, 0.0);
    EXPECT_DOUBLE_EQ(c.next(0.5), 0.25) << "follows the bound down at once (stiffening)";
    t.safety = 0.3;
    EXPECT_DOUBLE_EQ(TimeStepController(t).next(1.0), 0.3);
}

TEST(TimeStepController, CutsTheStepToTheShortestTimeInWhichABondFails) {
    TimeStepController c{TimeParams{}};
    c.next(1.0);
    c.record(0.5, 0, 40.0);  // a bond reaches eta_c (or overshoots it by delta) in 1/40 s
    EXPECT_DOUBLE_EQ(c.next(1.0), 0.025);
    EXPECT_EQ(c.lastLimit(), StepLimit::Stretch);
}

TEST(TimeStepController, ABurstOfBreakingShrinksTheNextStepsWhichRegrowByAtMostAQuarter) {
    TimeParams t;
    t.burstBonds = 8;
    TimeStepController c(t);
    c.next(1.0);
    c.record(0.5, 8, 0.0);
    EXPECT_DOUBLE_EQ(c.next(1.0), 0.5) << "eight bonds in one step are no burst";
    c.record(0.5, 32, 0.0);
    double dt = c.next(1.0);
    EXPECT_DOUBLE_EQ(dt, 0.125) << "four times the allowed breaks: a quarter of the step";
    EXPECT_EQ(c.lastLimit(), StepLimit::Burst);
    c.record(dt, 1000, 0.0);
    dt = c.next(1.0);
    EXPECT_DOUBLE_EQ(dt, 0.125 * TimeStepController::kMostShrink) << "one step cuts at most 8x";
    int steps = 0;
    for (double last = dt; dt < 0.5; last = dt, ++steps) {
        c.record(dt, 0, 0.0);
        dt = c.next(1.0);
        EXPECT_LE(dt, TimeStepController::kGrowth * last * (1 + 1e-15));
        EXPECT_GT(dt, last);
    }
    EXPECT_EQ(steps, 16) << "1/64 regrows to 0.5 by 1.25x a step: 1.25^16 > 32";
    EXPECT_EQ(c.largestBurst(), 1000u);
}

TEST(AdaptiveStep, LandsExactlyOnFrameTimes) {
    Membrane m(tearingSheet());
    for (int frame = 1; frame <= 6; ++frame) {
        m.advanceTo(frame / 24.0);
        EXPECT_EQ(m.time(), frame / 24.0) << "frame " << frame;
    }
    EXPECT_GT(m.stepCount(), 6) << "several steps per frame";
}

TEST(AdaptiveStep, NeverExceedsTheSafetyTimesTheStableBound) {
    MembraneParams p = tearingSheet();
    p.time.safety = 0.4;
    Membrane m(p);
    m.advanceTo(0.5);
    EXPECT_GT(m.brokenBondCount(), m.notchedBondCount()) << "the crack ran";
    EXPECT_LE(m.largestTimeStep(), 0.4 * m.stableTimeStep() * (1 + 1e-12));
    EXPECT_GE(m.largestTimeStep(), 0.39 * m.stableTimeStep()) << "and reaches it";
}

TEST(AdaptiveStep, NeverExceedsHalfTheStableBoundAtAutosSafety) {
    Membrane m(tearingSheet());  // safety 0.8
    m.advanceTo(0.5);
    EXPECT_LE(m.largestTimeStep(), 0.5 * m.stableTimeStep() * (1 + 1e-12));
    EXPECT_GE(m.largestTimeStep(), 0.49 * m.stableTimeStep()) << "and reaches it";
}

TEST(AdaptiveStep, ShrinksDuringABurstOfBreakingAndRegrows) {
    MembraneParams p = tearingSheet();
    p.time.burstBonds = 2;
    p.time.maxStretchIncrement = 1.0;  // the stretch limit alone keeps most bursts away
    Membrane m(p);
    const double full = TimeStepController::kMostOfBound * m.stableTimeStep();
    for (int frame = 1; frame <= 48; ++frame) m.advanceTo(frame / 24.0);
    const long* limits = m.stepController().limitCounts();
    EXPECT_GT(m.stepController().largestBurst(), 2u);
    EXPECT_GT(limits[int(StepLimit::Burst)], 0) << "bursts of more than 2 bonds cut the step";
    EXPECT_LT(m.smallestTimeStep(), 0.2 * full);
    // From 1/8 of the bound back to it: 9 steps limited by growth (1.25^9 = 7.5), then the bound.
    EXPECT_GE(limits[int(StepLimit::Growth)], 9) << "regrowing gradually";
    EXPECT_EQ(m.stepController().lastLimit(), StepLimit::Bound) << "back at the bound";
}

TEST(AdaptiveStep, OneAndTwoThreadsGiveIdenticalBits) {
    auto run = [](int threads) {
        omp_set_num_threads(threads);
        Membrane m(tearingSheet());
        EXPECT_GT(m.particleCount(), kParallelThreshold) << "must take the parallel path";
        for (int frame = 1; frame <= 12; ++frame) m.advanceTo(frame / 24.0);
        return std::tuple(m.positions(), m.damageState().bondAlive(), m.stepCount());
    };
    const auto [x1, alive1, steps1] = run(1);
    const auto [x2, alive2, steps2] = run(2);
    omp_set_num_threads(2);
    EXPECT_EQ(steps1, steps2);
    ASSERT_EQ(x1.size(), x2.size());
    EXPECT_EQ(std::memcmp(x1.data(), x2.data(), x1.size() * sizeof(x1[0])), 0);
    EXPECT_EQ(alive1, alive2);
    EXPECT_GT(std::count(alive1.begin(), alive1.end(), 0), 0) << "it tore";
}

TEST(AdaptiveStep, ABlowUpAdvisesALowerSafetyOrAFixedStep) {
    MembraneParams p = tearingSheet();
    p.time.safety = 0.7;
    Membrane m(p);
    m.advanceTo(0.1);
    const int free = m.nearestParticle({0.2, 0.2});  // away from the grips
    m.velocities()[free].x() = std::numeric_limits<double>::quiet_NaN();
    try {
        m.advanceTo(0.2);
        FAIL() << "the guard let a NaN through";
    } catch (const NumericalBlowUp& e) {
        EXPECT_EQ(e.particle, free);
        const std::string message = e.what();
        // 0.7 is above the half bound the adaptive step takes at most: it names what it took.
        EXPECT_NE(message.find("lower time.safety (now 0.5) or use a fixed dt <= "),
                  std::string::npos)
            << message;
    }
    Membrane fixed(p);  // step() alone is a fixed step: the usual advice
    fixed.velocities()[free].x() = std::numeric_limits<double>::quiet_NaN();
    try {
        fixed.step();
        FAIL() << "the guard let a NaN through";
    } catch (const NumericalBlowUp& e) {
        EXPECT_EQ(std::string(e.what()).find("time.safety"), std::string::npos) << e.what();
    }
}

TEST(AdaptiveStep, MeasuresStretchOnlyOnBondsLoadedTowardsBreaking) {
    MembraneParams p = tearingSheet();
    Membrane atRest(p);
    atRest.velocities()[0] = {-1, 0, 0};  // a corner moving out: fast, but its bonds are not loaded
    EXPECT_EQ(atRest.failureApproachRate(), 0.0);
    for (auto& x : atRest.positions()) x.y() *= 1.0 + atRest.referenceCriticalStretch();
    EXPECT_GT(atRest.failureApproachRate(), 1.0 / atRest.referenceCriticalStretch())
        << "stretched past eta_c / 2, the fast particle's bonds count";
    p.material.fractureEnergy.reset();
    Membrane unbreakable(p);
    EXPECT_EQ(unbreakable.failureApproachRate(), 0.0) << "nothing breaks: no stretch limit";
    EXPECT_FALSE(std::isfinite(unbreakable.referenceCriticalStretch()));
}

// The step resolves when a bond reaches eta_c, not how fast a loaded bond far from it rings: the
// same motion sets a step 10x shorter on a sheet at 0.99 eta_c (delta = 0.02 eta_c a step) than
// at 0.6 eta_c (half of the 0.4 eta_c to go).
TEST(AdaptiveStep, TheStepResolvesTheTimeABondTakesToReachItsCriticalStretch) {
    auto rateAt = [](double fraction, double speed) {
        MembraneParams p = tearingSheet();
        p.notches.clear();
        Membrane m(p);
        const double etaC = m.referenceCriticalStretch();
        for (int i = 0; i < m.particleCount(); ++i)
            m.positions()[i] = (1.0 + fraction * etaC) * m.restPositions()[i];
        const int centre = m.nearestParticle({0.0, 0.0});
        m.velocities()[centre] = {speed, 0, 0};
        return m.failureApproachRate();
    };
    const double far = rateAt(0.6, 1e-3), near = rateAt(0.99, 1e-3);
    EXPECT_GT(far, 0.0);
    EXPECT_NEAR(near / far, 0.2 / 0.02, 0.2) << "near " << near << ", far " << far;
    EXPECT_NEAR(rateAt(0.6, 2e-3), 2.0 * far, 1e-6 * far) << "in proportion to the stretch rate";
}

// Symplectic Euler kicks across the half steps either side when the step changes (which makes it
// velocity Verlet with variable steps). A sheet ringing in every lattice mode, stepped as the
// controller steps through bursts of breaking (cut at random to 1/8-9/10 of the step, regrown by
// 1.25x a step up to half the bound), keeps its energy; with a kick of the new step alone the
// step changes pump the lattice modes and the energy grows without bound, which is how the
// adaptive step shattered the seaweed flake.
TEST(AdaptiveStep, ChangingTheStepDoesNotPumpEnergyIntoTheLattice) {
    MembraneParams p = tearingSheet();
    p.material.fractureEnergy.reset();
    p.notches.clear();
    p.boundaries.clear();
    Membrane m(p);
    std::uint64_t state = 12345;
    auto uniform = [&state] {  // in [0, 1)
        state = state * 6364136223846793005ULL + 1442695040888963407ULL;
        return double(state >> 11) / double(1ULL << 53);
    };
    for (int i = 0; i < m.particleCount(); ++i)  // a seeded jitter: every mode rung
        m.positions()[i] =
            m.restPositions()[i] + 1e-5 * Eigen::Vector3d(uniform() - 0.5, uniform() - 0.5, 0);
    const double start = m.kineticEnergy() + m.strainEnergy();
    const double most = 0.5 * m.stableTimeStep();
    double dt = most, largest = start;
    for (int k = 0; k < 3000; ++k) {
        m.setTimeStep(dt);
        m.step();
        largest = std::max(largest, m.kineticEnergy() + m.strainEnergy());
        dt = uniform() < 0.05 ? std::max(0.125, 0.1 + 0.8 * uniform()) * dt
                              : std::min(most, 1.25 * dt);
    }
    EXPECT_LT(largest, 2.0 * start) << "start " << start << ", largest " << largest;
}

}  // namespace
}  // namespace rend::sim
