// The adaptive step's failure approach rate measured in the next step's force pass
// (Membrane::setApproachInPass, StepState::approach): the kernels flag the pairs loaded past half
// eta_c, the pass measures those, and the step's length is chosen after it. The same steps and
// bits as a pass of its own after every step, for every law, lattice, width and thread count;
// the laws and steps whose pass reads the step's length keep the pass of its own.

#include <gtest/gtest.h>
#include <omp.h>

#include <cstring>
#include <string>
#include <vector>

#include "sim/Membrane.h"

using namespace rend::sim;

namespace {

// A notched, heated 1 m sheet pulled apart: bonds load towards eta_c (the stretch limit chooses
// steps), break, and theta weakens and swells them.
MembraneParams tearingHeatedSheet(BondLawKind law, LatticeKind lattice) {
    MembraneParams p;
    p.sheet.size = {1.0, 0.6};
    p.sheet.dx = 0.015;
    p.sheet.lattice = lattice;
    p.sheet.thickness = 1e-3;
    p.material.youngsModulus = 2e4;
    p.material.density = 5000;
    p.material.law = law;
    p.material.powerLawRatio = -0.5;
    p.material.yieldStrain = 0.02;
    p.material.fractureEnergy = 0.5;
    p.material.conductivity = 0.01;
    p.material.expansion = 0.3;
    p.material.strengthLoss = 0.3;
    p.diffusion.spots.push_back({{0.1, 0.05}, 0.1, 20.0});
    p.notches = {Notch{{{-0.55, 0.001}, {-0.2, 0.001}}}};
    BoundaryCondition bottom, top;
    bottom.kind = top.kind = BoundaryKind::Velocity;
    bottom.region.max.y() = -0.29;
    top.region.min.y() = 0.29;
    bottom.velocity = {0, -0.3, 0};
    top.velocity = {0, 0.3, 0.02};
    p.boundaries = {bottom, top};
    p.time.dt.reset();
    p.time.control = StepControl::Adaptive;
    return p;
}

struct Advanced {
    std::vector<Eigen::Vector3d> x, v;
    std::vector<double> theta;
    std::vector<std::uint8_t> alive;
    std::vector<long> limits;
    long steps = 0, inPass = 0;
    std::size_t broken = 0;
};

constexpr int kFrames = 4;

Advanced advanced(const MembraneParams& p, bool inPass, int threads, double duration = 0.4) {
    omp_set_num_threads(threads);
    Membrane m(p);
    m.setApproachInPass(inPass);
    for (int f = 1; f <= kFrames; ++f) m.advanceTo(duration * f / kFrames);
    Advanced r;
    r.x = m.positions(), r.v = m.velocities(), r.theta = m.theta();
    r.alive = m.damageState().bondAlive();
    const long* counts = m.stepController().limitCounts();
    r.limits.assign(counts, counts + int(StepLimit::Count));
    r.steps = m.stepCount(), r.inPass = m.approachesInPass();
    r.broken = m.damageState().brokenBondCount();
    return r;
}

template <class T>
bool sameBits(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

void expectSameRun(const Advanced& a, const Advanced& b, const std::string& what) {
    EXPECT_EQ(a.steps, b.steps) << what;
    EXPECT_EQ(a.limits, b.limits) << what << ": the limits that chose the steps";
    EXPECT_TRUE(sameBits(a.x, b.x)) << what << ": positions";
    EXPECT_TRUE(sameBits(a.v, b.v)) << what << ": velocities";
    EXPECT_TRUE(sameBits(a.theta, b.theta)) << what << ": theta";
    EXPECT_TRUE(sameBits(a.alive, b.alive)) << what << ": bonds";
}

}  // namespace

TEST(ApproachInPass, TheForcePassMeasuresTheRateWithThePassOfItsOwnsBits) {
    for (const LatticeKind lattice : {LatticeKind::Hexagonal, LatticeKind::Square})
        for (const BondLawKind law : {BondLawKind::Linear, BondLawKind::Elastoplastic})
            for (const bool heated : {true, false}) {
                MembraneParams p = tearingHeatedSheet(law, lattice);
                if (!heated) p.diffusion.spots.clear(), p.material.conductivity = 0.0;
                const Advanced own = advanced(p, false, 1);
                const std::string name = "law " + std::to_string(int(law)) + ", lattice " +
                                         std::to_string(int(lattice)) + (heated ? ", heated" : "");
                EXPECT_EQ(own.inPass, 0) << name;
                EXPECT_EQ(own.theta.empty(), !heated) << name << ": with and without theta";
                EXPECT_GT(own.limits[int(StepLimit::Stretch)], 0)
                    << name << ": the rate must choose steps, or the test shows nothing";
                EXPECT_GT(own.broken, 0u) << name << ": the sheet must tear";
                for (const int threads : {1, 2}) {
                    const Advanced inPass = advanced(p, true, threads);
                    const std::string what = name + ", " + std::to_string(threads) + " threads";
                    // Every step's rate but each frame's last, which a pass of its own records so
                    // that a frame ends recorded (a checkpoint, the next frame).
                    EXPECT_EQ(inPass.inPass, inPass.steps - kFrames) << what;
                    expectSameRun(inPass, own, what);
                }
            }
}

// The power law's look-ahead reads the step's length, Velocity Verlet's pass sees half-kicked
// velocities, and an unbreakable sheet has no rate: each keeps its steps as they were.
TEST(ApproachInPass, WhatTheStepsLengthOrAHalfKickReachesKeepsThePassOfItsOwn) {
    MembraneParams power = tearingHeatedSheet(BondLawKind::PowerLaw, LatticeKind::Hexagonal);
    MembraneParams verlet = tearingHeatedSheet(BondLawKind::Linear, LatticeKind::Hexagonal);
    verlet.time.integrator = Integrator::VelocityVerlet;
    MembraneParams unbreakable = tearingHeatedSheet(BondLawKind::Linear, LatticeKind::Hexagonal);
    unbreakable.material.fractureEnergy.reset();
    for (const auto& [p, what] : {std::pair{power, "power law"}, std::pair{verlet, "Verlet"},
                                  std::pair{unbreakable, "unbreakable"}}) {
        const Advanced inPass = advanced(p, true, 2, 0.1);
        EXPECT_EQ(inPass.inPass, 0) << what;
        EXPECT_GT(inPass.steps, kFrames) << what;
        expectSameRun(inPass, advanced(p, false, 2, 0.1), what);
    }
}
