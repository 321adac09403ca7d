// Stability of the explicit scheme (README "Time stepping", "Blow-up guard"; VALIDATION.md "Stable
// explicit step (Silling & Askari 2005)" and "NaN / blow-up: stop within one step naming the
// particle and step"). Targets:
//  - dt = "auto" (0.8 x the bound) and dt = 1.0 x the bound stay bounded across E 1e1..1e10 Pa,
//    rho 10..1e4 kg/m^3, dx 1e-3..1e-1 m, with boundary speeds from 0 up to the wave speed;
//  - a dt above the bound is refused (SceneError) unless allow_unstable, and then a run that
//    diverges is stopped by the guard (NumericalBlowUp naming the step and the particle);
//  - a seeded fuzz of scenes always ends in a finite result or a clear error, never NaN;
//  - a burst of breaking bonds (every bond at once, or a cascade) leaves the state finite and
//    the energy bounded by what was stored.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>
#include <vector>

#include "app/Pipeline.h"
#include "app/Scene.h"
#include "app/SceneError.h"
#include "sim/Membrane.h"
#include "tests/ScratchDir.h"
#include "tests/sim/Peridynamic.h"

using namespace rend;
using namespace rend::sim;

namespace {

/// splitmix64 (Steele, Lea & Flood 2014): the test's own seeded stream.
class SplitMix {
public:
    explicit SplitMix(std::uint64_t seed) : state_(seed) {}
    std::uint64_t next() {
        std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
        return z ^ (z >> 31);
    }
    double uniform() { return double(next() >> 11) * 0x1.0p-53; }  ///< [0, 1)
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    double logUniform(double lo, double hi) {
        return std::exp(uniform(std::log(lo), std::log(hi)));
    }
    int integer(int lo, int hi) { return lo + int(next() % std::uint64_t(hi - lo + 1)); }
    bool chance(double p) { return uniform() < p; }

private:
    std::uint64_t state_;
};

/// Plane-stress P-wave speed of the bond-based membrane (nu = 1/3).
double waveSpeed(double E, double rho) { return std::sqrt(E / (rho * (1.0 - 1.0 / 9.0))); }

bool stateIsFinite(const Membrane& m) {
    for (int i = 0; i < m.particleCount(); ++i)
        if (!m.positions()[i].allFinite() || !m.velocities()[i].allFinite()) return false;
    return std::isfinite(m.kineticEnergy()) && std::isfinite(m.strainEnergy());
}

/// Seeded in-plane jitter of every particle, `amplitude` in metres.
void jitter(Membrane& m, double amplitude, std::uint64_t seed) {
    SplitMix rng(seed);
    for (auto& x : m.positions()) {
        x.x() += amplitude * rng.uniform(-1.0, 1.0);
        x.y() += amplitude * rng.uniform(-1.0, 1.0);
    }
}

/// A square sheet `cells` dx across whose left and right edges move apart at `speed`.
Scene tinyScene(double E, double rho, double dx, double speed, int cells = 11) {
    Scene s;
    s.file = "stability_test";
    s.locations["time.dt"] = "stability_test:time.dt";
    s.renderer = RendererKind::None;
    MembraneParams& p = s.sim;
    p.sheet.size = {cells * dx, cells * dx};
    p.sheet.dx = dx;
    p.material.youngsModulus = E;
    p.material.density = rho;
    BoundaryCondition left, right;
    left.kind = right.kind = BoundaryKind::Velocity;
    left.region.max.x() = -0.5 * cells * dx + 0.5 * dx;
    right.region.min.x() = 0.5 * cells * dx - 0.5 * dx;
    left.velocity = {-speed, 0, 0};
    right.velocity = {speed, 0, 0};
    p.boundaries = {left, right};
    return s;
}

double totalEnergy(const Membrane& m) { return m.kineticEnergy() + m.strainEnergy(); }

}  // namespace

TEST(Stability, AutoAndBoundTimeStepsStayBoundedAcrossTheParameterRange) {
    // Reference: Silling & Askari (2005) bound, README "Time stepping"; target: every corner of
    // E x rho x dx x boundary speed {0, wave speed}, at 0.8 and 1.0 x the bound, 300 steps
    // without NumericalBlowUp, finite, and (at rest boundaries) energy within 2x the initial.
    int runs = 0;
    double worstEnergyGrowth = 0.0, worstSpeedRatio = 0.0;
    for (double E : {1e1, 1e10})
        for (double rho : {10.0, 1e4})
            for (double dx : {1e-3, 1e-1})
                for (double speedShare : {0.0, 1.0})
                    for (double factor : {0.8, 1.0}) {
                        const double c = waveSpeed(E, rho);
                        Scene s = tinyScene(E, rho, dx, speedShare * c);
                        if (factor == 1.0)
                            s.sim.time.dt = Membrane(s.sim).stableTimeStep();  // exactly
                        Membrane m = prepareMembrane(s);
                        ASSERT_LE(m.timeStep(), m.stableTimeStep() * (1.0 + 1e-12));
                        jitter(m, 1e-3 * dx, 7);
                        const double e0 = totalEnergy(m);
                        double maxEnergy = e0, maxSpeed = 0.0;
                        const std::string what = "E " + std::to_string(E) + " rho " +
                                                 std::to_string(rho) + " dx " + std::to_string(dx) +
                                                 " speed " + std::to_string(speedShare) +
                                                 " c, dt " + std::to_string(factor) + " bound";
                        ASSERT_NO_THROW({
                            for (int k = 0; k < 300; ++k) {
                                m.step();
                                maxEnergy = std::max(maxEnergy, totalEnergy(m));
                                maxSpeed = std::max(maxSpeed, m.maxSpeed());
                            }
                        }) << what;
                        ASSERT_TRUE(stateIsFinite(m)) << what;
                        if (speedShare == 0.0) {
                            worstEnergyGrowth = std::max(worstEnergyGrowth, maxEnergy / e0);
                            EXPECT_LE(maxEnergy, 2.0 * e0) << what;
                        } else {
                            worstSpeedRatio =
                                std::max(worstSpeedRatio, maxSpeed / (speedShare * c));
                            EXPECT_LE(maxSpeed, 10.0 * speedShare * c) << what;
                        }
                        ++runs;
                    }
    std::printf(
        "[stability] %d corner runs bounded at 0.8 and 1.0 x the bound; largest energy / initial "
        "(jittered, boundaries at rest) %.4f; largest speed / boundary speed (edges at the wave "
        "speed) %.3f\n",
        runs, worstEnergyGrowth, worstSpeedRatio);
}

TEST(Stability, AStepAboveTheBoundIsRefusedUnlessAllowedAndThenStoppedByTheGuard) {
    // Reference: README "Time stepping" and "Blow-up guard", VALIDATION.md "NaN / blow-up";
    // target: dt = 1.01 x bound -> SceneError naming the limit; with allow_unstable, 4 x the
    // bound -> NumericalBlowUp naming a valid step and particle, with a suggested dt <= bound.
    int refused = 0, caught = 0;
    for (double E : {1e1, 1e10})
        for (double rho : {10.0, 1e4})
            for (double dx : {1e-3, 1e-1}) {
                Scene s = tinyScene(E, rho, dx, 0.1 * waveSpeed(E, rho));
                const double bound = Membrane(s.sim).stableTimeStep();
                s.sim.time.dt = 1.01 * bound;
                try {
                    prepareMembrane(s);
                    ADD_FAILURE() << "dt above the bound was accepted";
                } catch (const SceneError& e) {
                    EXPECT_NE(std::string(e.what()).find("stable limit"), std::string::npos);
                    ++refused;
                }
                s.sim.time.dt = 4.0 * bound;
                s.sim.time.allowUnstable = true;
                Membrane m = prepareMembrane(s);
                jitter(m, 1e-3 * dx, 11);
                try {
                    for (int k = 0; k < 300; ++k) m.step();
                    ADD_FAILURE() << "4 x the bound ran 300 steps without the guard";
                } catch (const NumericalBlowUp& e) {
                    EXPECT_GE(e.step, 1);
                    EXPECT_LE(e.step, m.stepCount());
                    EXPECT_GE(e.particle, 0);
                    EXPECT_LT(e.particle, m.particleCount());
                    EXPECT_LE(e.suggestedDt, bound);
                    EXPECT_NE(std::string(e.what()).find("numerical blow-up at step"),
                              std::string::npos);
                    ++caught;
                }
            }
    std::printf("[stability] dt above the bound: %d refused, %d caught by the guard at 4x\n",
                refused, caught);
}

namespace {

constexpr const char* kFuzzScene = R"(# base scene of the stability fuzz; every case overrides it
[sheet]
size = [0.1, 0.1]
dx = 0.01

[material]
E = 2e4
density = 5000

[[boundary]]
type = "velocity"
edge = "left"
velocity = [0.0, 0.0, 0.0]

[[boundary]]
type = "velocity"
edge = "right"
velocity = [0.0, 0.0, 0.0]

[time]
dt = "auto"
duration = 1.0

[render]
renderer = "none"
)";

constexpr const char* kNotch = R"(
[[notch]]
points = [[-1.0, 0.0], [0.0, 0.0]]
)";

std::string number(double v) {
    char text[40];
    std::snprintf(text, sizeof text, "%.17e", v);
    return text;
}

std::string vec(std::initializer_list<double> values) {
    std::string s = "[";
    for (double v : values) {
        if (s.size() > 1) s += ',';
        s += number(v);
    }
    return s + "]";
}

enum class Outcome { Ok, Refused, Caught };

}  // namespace

TEST(Stability, SeededParameterFuzzEndsInAResultOrAClearError) {
    // Reference: README "Errors" and "Blow-up guard"; target: 200 seeded scenes (E, rho, dx,
    // horizon, lattice, law, fracture, boundary velocities up to the wave speed, gravity,
    // damping, dt auto or 0.3-4 x the bound with or without allow_unstable, integrator, ~10% with
    // one invalid value), each a tiny sheet stepped 100-400 times: every case ends finite
    // (Ok), in a SceneError (Refused) or in NumericalBlowUp (Caught), with a clear message; at
    // dt <= the bound only the power law (stiffening without limit under compression) is caught.
    namespace fs = std::filesystem;
    const fs::path dir = test::scratchDir();
    fs::create_directories(dir);
    const fs::path plain = dir / "fuzz.toml", notched = dir / "fuzz_notch.toml";
    std::ofstream(plain) << kFuzzScene;
    std::ofstream(notched) << kFuzzScene << kNotch;

    SplitMix rng(0x5eed2024);
    const int kCases = 200;
    int ok = 0, refused = 0, caught = 0, caughtWithinBound = 0, invalidAsked = 0;
    for (int k = 0; k < kCases; ++k) {
        const double E = rng.logUniform(1e1, 1e10), rho = rng.logUniform(10.0, 1e4);
        const double dx = rng.logUniform(1e-3, 1e-1);
        const int cells = rng.integer(4, 14);
        const double size = cells * dx, c = waveSpeed(E, rho);
        std::vector<std::string> set = {
            "sheet.size=" + vec({size, size * rng.uniform(0.7, 1.3)}),
            "sheet.dx=" + number(dx),
            "sheet.horizon=" + number(rng.uniform(1.2, 3.0)),
            std::string("sheet.lattice=") + (rng.chance(0.8) ? "hexagonal" : "square"),
            "material.E=" + number(E),
            "material.density=" + number(rho),
            "forces.damping=" + number(rng.chance(0.5) ? 0.0 : rng.logUniform(1e-2, 1e2)),
            "time.integrator=" +
                std::string(rng.chance(0.5) ? "symplectic_euler" : "velocity_verlet"),
        };
        const int law = rng.integer(0, 2);
        if (law == 1) {
            set.push_back("material.law=power_law");
            set.push_back("material.power_ratio=" + number(rng.uniform(-0.15, 0.0)));
            set.push_back("material.power_exponent=" + number(rng.uniform(1.5, 6.0)));
        } else if (law == 2) {
            set.push_back("material.law=elastoplastic");
            set.push_back("material.yield_strain=" + number(rng.logUniform(1e-3, 0.3)));
            set.push_back("material.softening=" + number(rng.logUniform(0.05, 5.0)));
        }
        if (rng.chance(0.6)) {  // G_f such that eta_c ~ sqrt(G / (E dx)) spans 1e-3..0.5
            const double etaC = rng.logUniform(1e-3, 0.5);
            set.push_back("material.fracture_energy=" + number(etaC * etaC * E * dx));
            if (rng.chance(0.3)) set.push_back("material.critical_stretch=paper");
        }
        for (int b = 0; b < 2; ++b) {  // any direction, up to the wave speed
            Eigen::Vector3d dir(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
            const Eigen::Vector3d v = rng.uniform(0.0, 1.0) * c * dir.normalized();
            set.push_back("boundary." + std::to_string(b) +
                          ".velocity=" + vec({v.x(), v.y(), v.z()}));
            if (rng.chance(0.3))
                set.push_back("boundary." + std::to_string(b) +
                              ".ramp=" + number(rng.uniform(0.0, 1.0)));
        }
        if (rng.chance(0.3)) set.push_back("forces.gravity=" + vec({0.0, 0.0, -9.81}));
        double dtFactor = 0.0;  // 0: "auto"
        if (rng.chance(0.5)) {
            dtFactor = rng.chance(0.5) ? rng.uniform(0.3, 1.0) : rng.uniform(1.0, 4.0);
            if (rng.chance(0.5)) set.push_back("time.allow_unstable=true");
        }
        if (rng.chance(0.1)) {  // one invalid value: must be refused with a clear message
            ++invalidAsked;
            static const char* kBad[] = {"material.E=-5",          "sheet.horizon=7",
                                         "material.density=0",     "material.law=plastic",
                                         "time.safety=1.5",        "sheet.dx=-0.01",
                                         "boundary.0.type=pinned", "time.dt=0"};
            set.push_back(kBad[rng.integer(0, 7)]);
        }
        const bool withNotch = rng.chance(0.3);
        const int steps = rng.integer(100, 400);
        const std::string label = "case " + std::to_string(k);

        Outcome outcome = Outcome::Ok;
        double dtOverBound = 0.0, dtRun = 0.0;
        // Runs the case with its step divided by `finer`; returns the time it reached.
        auto run = [&](int finer) {
            Scene scene = loadScene(withNotch ? notched : plain, set);
            {  // the step this scene gets, to make `steps` steps one frame long
                const double bound = prepareMembrane(scene).stableTimeStep();
                if (dtFactor > 0.0) scene.sim.time.dt = dtFactor * bound;
                const double dt = scene.sim.time.dt.value_or(scene.sim.time.safety * bound);
                scene.sim.time.duration = steps * dt;
                scene.sim.time.fps = 1.0 / scene.sim.time.duration;
            }
            Membrane m = prepareMembrane(scene);
            const auto [substeps, dt] = substepsPerFrame(m.timeStep(), scene.sim.time.fps);
            m.setTimeStep(dt / finer);
            dtRun = dt;
            dtOverBound = dt / m.stableTimeStep();
            jitter(m, 1e-3 * dx, std::uint64_t(k));
            for (int s = 0; s < substeps * finer; ++s) m.step();
            return m;
        };
        try {
            Membrane m = run(1);
        } catch (const SceneError& e) {
            outcome = Outcome::Refused;
            EXPECT_NE(std::string(e.what()).find("error:"), std::string::npos)
                << label << ": " << e.what();
        } catch (const NumericalBlowUp& e) {
            outcome = Outcome::Caught;
            EXPECT_NE(std::string(e.what()).find("numerical blow-up at step"), std::string::npos)
                << label;
            EXPECT_GE(e.particle, 0) << label;
            EXPECT_GT(e.suggestedDt, 0.0) << label;
            if (dtOverBound <= 1.0 + 1e-12) {
                ++caughtWithinBound;
                // Within the bound only the power law may blow up, and then not for the step's
                // sake: its tangent turns negative in tension when c* < 0 (a material
                // instability), or a boundary crushes it faster than sound. The proof is that a
                // step four times finer blows up at about the same time.
                EXPECT_EQ(law, 1) << label << ": a linear or elastoplastic run blew up within "
                                  << "the bound: " << e.what();
                const double tFirst = e.step * dtRun;
                double tFine = -1.0;
                try {
                    run(4);
                } catch (const NumericalBlowUp& fine) {
                    tFine = fine.step * dtRun / 4;
                }
                std::printf(
                    "[stability] %s (law %d) caught at dt = %.3f x the rest bound at t = %.4g s; "
                    "at dt / 4 at t = %.4g s\n",
                    label.c_str(), law, dtOverBound, tFirst, tFine);
                EXPECT_GT(tFine, 0.0) << label << ": a finer step survives, so dt was too large";
                EXPECT_NEAR(tFine, tFirst, 0.5 * tFirst + 2 * dtRun) << label;
            }
        } catch (const std::exception& e) {
            ADD_FAILURE() << label << ": unexpected exception " << e.what();
        }
        ok += outcome == Outcome::Ok;
        refused += outcome == Outcome::Refused;
        caught += outcome == Outcome::Caught;
    }
    std::printf(
        "[stability] fuzz of %d seeded scenes: %d ok, %d refused (%d asked with an invalid "
        "value), %d caught by the guard (%d of them at dt <= the bound, all power law)\n",
        kCases, ok, refused, invalidAsked, caught, caughtWithinBound);
    EXPECT_EQ(ok + refused + caught, kCases);
    EXPECT_GE(refused, invalidAsked);
}

TEST(Stability, BurstsOfBreakingBondsStayFiniteWithBoundedEnergy) {
    // Reference: README "Fracture"; target: for every law, (a) a sheet stretched to 1.05 eta_c
    // everywhere breaks every bond in one step and stays finite at rest; (b) a sheet at
    // 0.97 eta_c with seeded jitter breaks in a cascade, stays finite, and its kinetic plus
    // strain energy never exceeds 1.05 x what it stored at the start.
    for (BondLawKind law :
         {BondLawKind::Linear, BondLawKind::PowerLaw, BondLawKind::Elastoplastic}) {
        MembraneParams p;
        p.sheet.size = {0.4, 0.4};
        p.sheet.dx = 0.02;
        p.material.youngsModulus = 2e4;
        p.material.density = 5000;
        p.material.fractureEnergy = 2.0;  // eta_c = 0.072
        p.material.law = law;
        p.material.powerLawRatio = -0.1;
        p.material.yieldStrain = 0.06;
        p.material.softening = 0.5;

        Membrane all(p);
        const double etaC = rend::test::criticalStretch(all);
        for (int i = 0; i < all.particleCount(); ++i)
            all.positions()[i] = (1.0 + 1.05 * etaC) * all.restPositions()[i];
        for (int k = 0; k < 200; ++k) all.step();
        EXPECT_EQ(all.brokenBondCount(), all.bondCount()) << "law " << int(law);
        EXPECT_TRUE(stateIsFinite(all)) << "law " << int(law);
        EXPECT_EQ(all.kineticEnergy(), 0.0) << "law " << int(law) << ": nothing left to push";

        Membrane cascade(p);
        for (int i = 0; i < cascade.particleCount(); ++i)
            cascade.positions()[i] = (1.0 + 0.97 * etaC) * cascade.restPositions()[i];
        jitter(cascade, 0.05 * etaC * p.sheet.dx, 3);
        const double e0 = totalEnergy(cascade);
        double worst = 0.0;
        std::size_t brokenEarly = 0;
        for (int k = 0; k < 600; ++k) {
            cascade.step();
            if (k == 0) brokenEarly = cascade.brokenBondCount();
            worst = std::max(worst, totalEnergy(cascade) / e0);
        }
        EXPECT_TRUE(stateIsFinite(cascade)) << "law " << int(law);
        EXPECT_LE(worst, 1.05) << "law " << int(law);
        EXPECT_GT(cascade.brokenBondCount(), cascade.bondCount() / 4) << "law " << int(law);
        std::printf(
            "[stability] burst, law %d: all %zu bonds broken in one step; cascade broke %zu in "
            "its first step and %zu (%.0f%%) in 600, energy at most %.4f x the stored\n",
            int(law), all.bondCount(), brokenEarly, cascade.brokenBondCount(),
            100.0 * double(cascade.brokenBondCount()) / double(cascade.bondCount()), worst);
    }
}

TEST(Stability, PowerLawCrushAndReboundStaysBoundedUnderAutoDt) {
    // Reference: README "Time stepping"; target: the power law stiffens as s^-4 in compression,
    // beyond the rest bound that dt = "auto" is taken at. A sheet thrown inwards on itself
    // (v = -gamma x) is crushed to about half its size and springs back: with each step cut into
    // sqrt(stiffening) pieces it stays finite and keeps its energy within 2% (Verlet) or 20%
    // (symplectic Euler, first order). Without the pieces both blow up within five steps.
    for (Integrator integrator : {Integrator::SymplecticEuler, Integrator::VelocityVerlet}) {
        MembraneParams p;
        p.sheet.size = {0.2, 0.2};
        p.sheet.dx = 0.02;
        p.material.youngsModulus = 2e4;
        p.material.density = 500;
        p.material.law = BondLawKind::PowerLaw;
        p.time.integrator = integrator;
        Membrane m(p);
        const double c = std::sqrt(p.material.youngsModulus / p.material.density);
        const double gamma = 3.0 * c / 0.1;  // the corners start at 3 c: s_min ~ 0.55
        for (int i = 0; i < m.particleCount(); ++i)
            m.velocities()[i] = -gamma * m.restPositions()[i];
        const double e0 = totalEnergy(m);
        double lowest = 1.0, worst = 0.0;
        const int steps = int(0.1 / c / m.timeStep());  // in and out again
        for (int k = 0; k < steps; ++k) {
            m.step();
            lowest = std::min(lowest, (m.positions()[0] - m.positions()[1]).norm() /
                                          (m.restPositions()[0] - m.restPositions()[1]).norm());
            worst = std::max(worst, std::abs(totalEnergy(m) / e0 - 1));
        }
        std::printf(
            "[stability] power-law crush and rebound (%s): %d steps cut into %ld extra "
            "pieces, smallest edge stretch %.3f, energy within %.2e of the start\n",
            integrator == Integrator::VelocityVerlet ? "Verlet" : "symplectic Euler", steps,
            m.extraSubsteps(), lowest, worst);
        EXPECT_TRUE(stateIsFinite(m));
        EXPECT_LT(lowest, 0.6) << "the crush must reach the stiff part of the law";
        EXPECT_GT(m.extraSubsteps(), 0);
        EXPECT_LT(worst, integrator == Integrator::VelocityVerlet ? 0.02 : 0.2);
    }
}
