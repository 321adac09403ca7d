// Issue 14: a run restarted from a checkpoint steps on with the same bits as one that never
// stopped, for every solver and law, with diffusion, fracture, plasticity and contact.

#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <vector>

#include "sim/Membrane.h"
#include "sim/SolverRegistry.h"
#include "tests/sim/ThreadCheck.h"

using namespace rend::sim;

namespace {

/// A notched sheet pulled apart by grips, heated by a spot: it stretches, yields, tears and
/// diffuses within the run.
MembraneParams tearingSheet(BondLawKind law, const std::string& solver) {
    MembraneParams p;
    p.solver = solver;
    p.sheet.size = {1.0, 0.5};
    p.sheet.dx = 0.05;
    p.sheet.perturbationAmplitude = 1e-3;
    p.material.youngsModulus = 2e4;
    p.material.density = 5000;
    p.material.law = law;
    p.material.yieldStrain = 0.01;
    p.material.powerLawRatio = -0.1;
    p.material.fractureEnergy = 0.5;
    p.material.conductivity = 1e-3;
    p.material.expansion = 0.05;
    p.material.strengthLoss = 0.3;
    p.diffusion.spots.push_back(DiffusionSpot{{0.1, 0.0}, 0.15, 2.0});
    p.notches = {Notch{{{-0.55, 0.001}, {-0.2, 0.001}}}};
    p.boundaries = support::pullingGrips();
    p.boundaries[0].velocity.y() = 0.3;
    return p;
}

/// Two pieces, the upper laid over the lower, on the ground: self-contact and the ground.
MembraneParams stackedPieces() {
    MembraneParams p;
    p.sheet.size = {0.2, 0.4};
    p.sheet.dx = 0.02;
    p.material.youngsModulus = 2e4;
    p.material.density = 5000;
    p.gravity = {0, 0, -9.81};
    p.contact.ground.enabled = true;
    p.contact.self.enabled = true;
    p.sheet.center.z() = 0.005;
    p.notches.push_back(Notch{{{-0.2, 0.006}, {0.2, 0.006}}});
    p.damping = 2.0;
    return p;
}

void layUpperOverLower(Membrane& m) {
    for (int i = 0; i < m.particleCount(); ++i)
        if (m.restPositions()[i].y() > 0.006) m.positions()[i] += Eigen::Vector3d(0, -0.2, 0.03);
}

struct Snapshot {
    std::vector<Eigen::Vector3d> x, v;
    std::vector<double> theta, damage;
    std::vector<std::uint8_t> alive, kept;
    double time;
    long steps;
};

Snapshot snapshot(const Membrane& m) {
    return {m.positions(),
            m.velocities(),
            m.theta(),
            m.damage(),
            m.damageState().bondAlive(),
            m.damageState().keptTriangles(),
            m.time(),
            m.stepCount()};
}

template <class T>
bool sameBits(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

void expectSameBits(const Snapshot& a, const Snapshot& b) {
    EXPECT_TRUE(sameBits(a.x, b.x)) << "positions";
    EXPECT_TRUE(sameBits(a.v, b.v)) << "velocities";
    EXPECT_TRUE(sameBits(a.theta, b.theta)) << "theta";
    EXPECT_TRUE(sameBits(a.damage, b.damage)) << "damage";
    EXPECT_EQ(a.alive, b.alive);
    EXPECT_EQ(a.kept, b.kept);
    EXPECT_EQ(a.time, b.time);
    EXPECT_EQ(a.steps, b.steps);
}

/// Frames as rend run steps them: startFrame, then adaptive steps to the frame's time or a
/// fixed count of steps.
void runFrames(Membrane& m, int first, int last, double frameTime, int fixedSteps) {
    for (int frame = first; frame <= last; ++frame) {
        m.startFrame();
        if (fixedSteps > 0)
            for (int k = 0; k < fixedSteps; ++k) m.step();
        else
            m.advanceTo(frame * frameTime);
        m.updateDamage();
    }
}

/// Runs `frames` frames straight through, and again from a checkpoint taken after `at` into a
/// membrane built afresh (set up by `prepare`, as a scene would be), and compares the bits.
/// Returns the broken bonds of the full run.
std::size_t expectResumedRunMatches(const MembraneParams& p, int frames, int at, double frameTime,
                                    int fixedSteps = 0,
                                    const std::function<void(Membrane&)>& prepare = {}) {
    Membrane straight(p);
    if (prepare) prepare(straight);
    runFrames(straight, 1, at, frameTime, fixedSteps);
    const std::vector<std::byte> checkpoint = straight.saveState();
    // Written into a last frame's storage (longer, and not empty), the same bytes.
    EXPECT_EQ(straight.saveState(std::vector<std::byte>(checkpoint.size() + 99, std::byte{7})),
              checkpoint);
    runFrames(straight, at + 1, frames, frameTime, fixedSteps);

    Membrane resumed(p);
    if (prepare) prepare(resumed);
    resumed.loadState(checkpoint);
    runFrames(resumed, at + 1, frames, frameTime, fixedSteps);
    expectSameBits(snapshot(straight), snapshot(resumed));
    EXPECT_GT(straight.stepCount(), 0);
    if (straight.contact()) {
        // The same lists: both runs rebuild at each frame's start, so neither reads a list the
        // other lacks (which may order its contacts' sums differently).
        EXPECT_EQ(straight.contact()->listBuilds(), resumed.contact()->listBuilds());
        EXPECT_EQ(straight.contact()->moverEvaluations(), resumed.contact()->moverEvaluations());
    }
    return straight.brokenBondCount();
}

}  // namespace

TEST(Checkpoint, EveryLawResumesWithTheSameBits) {
    for (const BondLawKind law :
         {BondLawKind::Linear, BondLawKind::PowerLaw, BondLawKind::Elastoplastic}) {
        SCOPED_TRACE(int(law));
        const std::size_t broken =
            expectResumedRunMatches(tearingSheet(law, "peridynamic"), 8, 4, 0.1);
        EXPECT_GT(broken, 0u) << "the run tears after the checkpoint";
    }
}

TEST(Checkpoint, EverySolverResumesWithTheSameBits) {
    for (const SolverEntry& entry : solverRegistry()) {
        SCOPED_TRACE(entry.name);
        MembraneParams p = tearingSheet(BondLawKind::Elastoplastic, std::string(entry.name));
        if (!entry.supports.bondLaws) p.material.law = BondLawKind::Linear;
        ASSERT_EQ(unsupportedFeatures(entry, p), "");
        expectResumedRunMatches(p, 6, 3, 0.1);
    }
}

TEST(Checkpoint, FixedStepsAndVelocityVerletResumeWithTheSameBits) {
    MembraneParams p = tearingSheet(BondLawKind::Linear, "peridynamic");
    p.time.integrator = Integrator::VelocityVerlet;
    p.time.dt = 2e-3;
    expectResumedRunMatches(p, 8, 5, 0.0, 40);
}

TEST(Checkpoint, ContactResumesWithTheSameBits) {
    const MembraneParams p = stackedPieces();
    Membrane probe(p);
    layUpperOverLower(probe);
    probe.advanceTo(0.4);
    ASSERT_GT(probe.contact()->lastPairCount(), 0u) << "the pieces touch by then";
    expectResumedRunMatches(p, 20, 9, 0.04, 0, layUpperOverLower);
}

TEST(Checkpoint, AnotherScenesStateIsRefused) {
    const Membrane coarse(tearingSheet(BondLawKind::Linear, "peridynamic"));
    MembraneParams finer = tearingSheet(BondLawKind::Linear, "peridynamic");
    finer.sheet.dx = 0.04;
    Membrane other(finer);
    EXPECT_THROW(other.loadState(coarse.saveState()), StateMismatch);
    std::vector<std::byte> state = coarse.saveState();
    Membrane same(tearingSheet(BondLawKind::Linear, "peridynamic"));
    state.pop_back();
    EXPECT_THROW(same.loadState(state), StateMismatch) << "truncated";
    state = coarse.saveState();
    state.push_back(std::byte{0});
    EXPECT_THROW(same.loadState(state), StateMismatch) << "bytes left over";
    MembraneParams withContact = tearingSheet(BondLawKind::Linear, "peridynamic");
    withContact.contact.ground.enabled = true;
    Membrane contact(withContact);
    EXPECT_THROW(contact.loadState(coarse.saveState()), StateMismatch);
}
