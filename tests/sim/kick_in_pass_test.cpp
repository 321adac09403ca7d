// The kick and drift inside the force pass (Membrane::setKickInPass, StepState::motion): the
// same bits as the separate pass after it, for every law, thread count and kind of step it
// takes, and the separate pass wherever a step may not take it.

#include <gtest/gtest.h>
#include <omp.h>

#include <cstring>
#include <string>
#include <vector>

#include "sim/Membrane.h"

using namespace rend::sim;

namespace {

// A notched 1 m sheet pulled apart at dt 1e-4, breaking, with a source heating (and expanding)
// it: every branch of the pass (theta, breaking, the elastoplastic history).
MembraneParams pulledSheet(BondLawKind law) {
    MembraneParams p;
    p.sheet.size = {1.0, 0.6};
    p.sheet.dx = 0.01;
    p.sheet.lattice = LatticeKind::Square;
    p.sheet.thickness = 1e-3;
    p.material.youngsModulus = 2e4;
    p.material.density = 5000;
    p.material.law = law;
    p.material.powerLawRatio = -0.5;
    p.material.yieldStrain = 2e-3;
    p.material.fractureEnergy = 0.05;
    p.material.conductivity = 0.01;
    p.material.expansion = 0.5;
    p.material.strengthLoss = 0.3;
    p.diffusion.spots.push_back({{0.1, 0.05}, 0.1, 20.0});
    BoundaryCondition bottom, top;
    bottom.kind = top.kind = BoundaryKind::Velocity;
    bottom.region.max.y() = -0.29;
    top.region.min.y() = 0.29;
    bottom.velocity = {0, -0.5, 0};
    top.velocity = {0, 0.5, 0.05};
    p.boundaries = {bottom, top};
    p.damping = 1.0;
    p.time.dt = 1e-4;
    return p;
}

struct Steps {
    std::vector<Eigen::Vector3d> x, v;
    std::vector<double> theta;
    std::vector<std::uint8_t> alive;
    bool keptInPass = true;  ///< every step's
    int stepsInPass = 0;     ///< the steps whose force pass moved the particles
    long extraPieces = 0;    ///< Membrane::extraSubsteps()
    std::size_t broken = 0;
    double budget = 0.0;   ///< the blow-up guard's: the driven particles' forces times velocities
    double kinetic = 0.0;  ///< the blow-up guard's sum over the free particles
};

Steps stepped(const MembraneParams& p, bool inPass, int threads, int steps) {
    omp_set_num_threads(threads);
    Membrane m(p);
    m.setKickInPass(inPass);
    Steps r;
    for (int s = 0; s < steps; ++s) {
        m.step();
        r.keptInPass = r.keptInPass && m.keptKickInPass();
        r.stepsInPass += m.keptKickInPass();
    }
    r.extraPieces = m.extraSubsteps();
    r.x = m.positions(), r.v = m.velocities(), r.theta = m.theta();
    r.alive = m.damageState().bondAlive();
    r.broken = m.damageState().brokenBondCount();
    r.budget = m.energyBudget();
    r.kinetic = m.checkedKinetic();
    return r;
}

template <class T>
bool sameBits(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

void expectSameBits(const Steps& a, const Steps& b, const std::string& what) {
    EXPECT_TRUE(sameBits(a.x, b.x)) << what << ": positions";
    EXPECT_TRUE(sameBits(a.v, b.v)) << what << ": velocities";
    EXPECT_TRUE(sameBits(a.theta, b.theta)) << what << ": theta";
    EXPECT_TRUE(sameBits(a.alive, b.alive)) << what << ": bonds";
    EXPECT_EQ(std::memcmp(&a.budget, &b.budget, sizeof a.budget), 0)
        << what << ": the guard's budget " << a.budget << " against " << b.budget;
    EXPECT_EQ(std::memcmp(&a.kinetic, &b.kinetic, sizeof a.kinetic), 0)
        << what << ": the guard's kinetic energy " << a.kinetic << " against " << b.kinetic;
}

}  // namespace

TEST(KickInPass, TheForcePassMovesEveryLawWithTheSeparatePassesBits) {
    for (const BondLawKind law :
         {BondLawKind::Linear, BondLawKind::Elastoplastic, BondLawKind::PowerLaw}) {
        const MembraneParams p = pulledSheet(law);
        const Steps after = stepped(p, false, 1, 250);
        EXPECT_FALSE(after.keptInPass);
        EXPECT_GT(after.broken, 0u) << "the sheet must break";
        for (const int threads : {1, 2}) {
            const Steps inPass = stepped(p, true, threads, 250);
            const std::string what =
                "law " + std::to_string(int(law)) + ", " + std::to_string(threads) + " threads";
            // The power law's look-ahead may cut a step into pieces only once its pass is
            // done: its first step, with no pass before it to bound the pairs, keeps the
            // separate pass.
            if (law == BondLawKind::PowerLaw)
                EXPECT_EQ(inPass.stepsInPass, 249) << what;
            else
                EXPECT_TRUE(inPass.keptInPass) << what;
            expectSameBits(inPass, after, what);
        }
    }
}

// A power-law sheet squeezed at a step near its stable one: the look-ahead stiffens it and cuts
// steps into pieces. Each step's pass moves the particles only where the last pass shows that
// no pair can stiffen it (else the step would throw), and the bits are the separate pass's.
TEST(KickInPass, ThePowerLawMovesInItsPassOnlyWhereNoPairCanStiffenTheStep) {
    MembraneParams p = pulledSheet(BondLawKind::PowerLaw);
    p.material.fractureEnergy.reset();
    p.material.powerLawRatio = 0.0;
    p.diffusion.spots[0].rate = 2.0;
    p.boundaries[0].velocity = {0, 0.2, 0};
    p.boundaries[1].velocity = {0, -0.2, 0.05};
    p.boundaries[0].rampTime = p.boundaries[1].rampTime = 0.01;
    Membrane probe(p);
    p.time.dt = 0.3 * probe.stableTimeStep();
    const int steps = 400;
    const Steps after = stepped(p, false, 1, steps);
    EXPECT_GT(after.extraPieces, 0) << "the squeeze must stiffen some steps";
    for (const int threads : {1, 2}) {
        const Steps inPass = stepped(p, true, threads, steps);
        const std::string what = std::to_string(threads) + " threads";
        EXPECT_GT(inPass.stepsInPass, steps / 10) << what;
        EXPECT_LT(inPass.stepsInPass, steps - after.extraPieces) << what;
        EXPECT_EQ(inPass.extraPieces, after.extraPieces) << what;
        expectSameBits(inPass, after, what);
    }
}

// The ground alone pushes the particles out after the drift, as after the separate pass; a
// collider may cut the step, and pressure adds to the forces after the pass: those keep the
// separate pass.
TEST(KickInPass, TheGroundKeepsItAndWhatMayCutOrAddToTheStepDoesNot) {
    MembraneParams p = pulledSheet(BondLawKind::Linear);
    p.boundaries.clear();
    p.gravity = {0, 0, -9.81};
    p.contact.ground.enabled = true;
    p.contact.ground.height = -0.004;
    const Steps after = stepped(p, false, 2, 300);
    const Steps inPass = stepped(p, true, 2, 300);
    EXPECT_TRUE(inPass.keptInPass);
    expectSameBits(inPass, after, "on the ground");
    double lowest = 1.0;
    for (const Eigen::Vector3d& x : inPass.x) lowest = std::min(lowest, x.z());
    EXPECT_GE(lowest, -0.0015 - 1e-12) << "the ground (its height plus half the contact "
                                          "thickness) holds the sheet";
    EXPECT_LT(lowest, -0.0014) << "the sheet fell onto the ground";

    MembraneParams collider = p;
    collider.contact.colliders.push_back({});
    collider.contact.colliders.back().position = {0, 0, -1.0};
    collider.contact.colliders.back().radius = 0.2;
    EXPECT_FALSE(stepped(collider, true, 1, 3).keptInPass);
    MembraneParams pressure = pulledSheet(BondLawKind::Linear);
    pressure.pressure = 1.0;
    EXPECT_FALSE(stepped(pressure, true, 1, 3).keptInPass);
    MembraneParams verlet = pulledSheet(BondLawKind::Linear);
    verlet.time.integrator = Integrator::VelocityVerlet;
    EXPECT_FALSE(stepped(verlet, true, 1, 3).keptInPass);
}

// The blow-up guard's sample of the motion is taken block by block as the pass moves them: an
// unstable step stops at the same step with the same report.
TEST(KickInPass, TheGuardStopsAnUnstableSheetAtTheSameStep) {
    MembraneParams p = pulledSheet(BondLawKind::Linear);
    p.material.fractureEnergy.reset();  // unbreakable: it cannot shatter before it blows up
    p.damping = 0.0;
    auto blowUp = [&](bool inPass, int threads) {
        omp_set_num_threads(threads);
        Membrane m(p);
        m.setKickInPass(inPass);
        m.setTimeStep(2.5 * m.stableTimeStep());
        for (int s = 0; s < 3000; ++s) try {
                m.step();
            } catch (const NumericalBlowUp& e) {
                return std::to_string(s) + ": " + e.what();
            }
        return std::string("no blow-up");
    };
    const std::string after = blowUp(false, 1);
    EXPECT_NE(after, "no blow-up");
    EXPECT_EQ(blowUp(true, 1), after);
    EXPECT_EQ(blowUp(true, 2), after);
}
