// The solvers of sim/Solver.h (peridynamic bonds, FEM CST, Van Gelder and two-parameter
// mass-spring, SPH) on the same lattice, boundaries and integrators.

#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <numbers>
#include <set>
#include <sstream>
#include <utility>

#include "sim/FemCst.h"
#include "sim/MassSpring.h"
#include "sim/Membrane.h"
#include "sim/PeridynamicBonds.h"
#include "sim/Random.h"
#include "sim/SolverRegistry.h"
#include "tests/sim/ErodedElement.h"
#include "tests/sim/Peridynamic.h"
#include "tests/sim/ThreadCheck.h"

using namespace rend::sim;

namespace {

const std::string kSolvers[] = {"peridynamic",    "fem_cst", "mass_spring_vg",
                                "mass_spring_tp", "sph",     "mpm"};

MembraneParams sheet(std::string solver, double nu, double width = 0.4, double height = 0.4) {
    MembraneParams p;
    p.solver = solver;
    p.sheet.size = {width, height};
    p.sheet.dx = 0.02;
    p.material.youngsModulus = 2e4;
    p.material.poissonRatio = nu;
    p.material.density = 5000;
    return p;
}

double maxNorm(const std::vector<Eigen::Vector3d>& f) {
    double m = 0.0;
    for (const auto& v : f) m = std::max(m, v.norm());
    return m;
}

void jitter(Membrane& m, double amplitude, std::uint64_t seed) {
    for (int i = 0; i < m.particleCount(); ++i)
        for (int a = 0; a < 3; ++a)
            m.positions()[i][a] +=
                amplitude * (2.0 * uniformFromHash(seed, std::uint64_t(3 * i + a)) - 1.0);
}

}  // namespace

TEST(Solvers, RigidMotionGivesZeroForce) {
    for (std::string s : kSolvers) {
        Membrane m(sheet(s, 0.3));
        jitter(m, 2e-3, 5);  // a deformed state, then moved rigidly
        std::vector<Eigen::Vector3d> before, after;
        m.computeForces(before);
        const Eigen::Matrix3d R =
            Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
        for (auto& x : m.positions()) x = R * x + Eigen::Vector3d(0.3, -1.0, 2.0);
        m.computeForces(after);
        double worst = 0.0;
        for (int i = 0; i < m.particleCount(); ++i)
            worst = std::max(worst, (after[i] - R * before[i]).norm());
        EXPECT_LT(worst, 1e-10 * maxNorm(before)) << s.c_str() << ": forces turn with the body";

        for (int i = 0; i < m.particleCount(); ++i) m.positions()[i] = m.restPositions()[i];
        for (auto& x : m.positions()) x = R * x + Eigen::Vector3d(0.3, -1.0, 2.0);
        m.computeForces(after);
        EXPECT_LT(maxNorm(after), 1e-12 * maxNorm(before) * 1e3) << s.c_str() << " at rest";
        Eigen::Vector3d total = Eigen::Vector3d::Zero();
        for (const auto& f : before) total += f;
        EXPECT_LT(total.norm(), 1e-12 * maxNorm(before) * m.particleCount()) << s.c_str();
    }
}

TEST(Solvers, BondFemAndSphForcesAreMinusTheGradientOfTheStrainEnergy) {
    struct Case {
        std::string solver;
        BondLawKind law;
    };
    const Case cases[] = {{"peridynamic", BondLawKind::Linear},
                          {"peridynamic", BondLawKind::PowerLaw},
                          {"peridynamic", BondLawKind::Elastoplastic},
                          {"fem_cst", BondLawKind::Linear},
                          {"sph", BondLawKind::Linear}};
    for (const auto& [s, law] : cases) {
        MembraneParams p = sheet(s, 0.3, 0.12, 0.12);
        p.material.law = law;
        p.material.powerLawRatio = -0.05;
        p.material.yieldStrain = 0.5;  // elastic here: the energy is a potential
        p.material.expansion = 0.01;   // and a warm, softened sheet
        p.material.stiffnessLoss = 0.3;
        p.diffusion.initial = 0.5;
        Membrane m(p);
        jitter(m, 3e-3, 9);
        std::vector<Eigen::Vector3d> f;
        m.computeForces(f);
        const double h = 1e-7;
        double worst = 0.0;
        for (int i = 0; i < m.particleCount(); i += 3)
            for (int a = 0; a < 3; ++a) {
                const double keep = m.positions()[i][a];
                m.positions()[i][a] = keep + h;
                const double up = m.strainEnergy();
                m.positions()[i][a] = keep - h;
                const double down = m.strainEnergy();
                m.positions()[i][a] = keep;
                worst = std::max(worst, std::abs(-(up - down) / (2 * h) - f[i][a]));
            }
        EXPECT_LT(worst, 1e-6 * maxNorm(f)) << s.c_str() << " law " << int(law);
    }
}

TEST(Solvers, ThePeridynamicBondsAreASolverOnTheMembranesOwnBonds) {
    // The default solver is the paper's bonds behind the same interface: they break the shared
    // bonds through the DamageState it is bound to, report the power law's stiffening in
    // compression, and give the damage field eq. 27's strength left of yielded bonds.
    MembraneParams p = sheet("peridynamic", 0.3, 0.2, 0.2);
    p.material.fractureEnergy = 0.02;
    Membrane m(p);
    const auto* bonds = dynamic_cast<const PeridynamicBonds*>(&m.solver());
    ASSERT_NE(bonds, nullptr);
    EXPECT_EQ(bonds->criticalStretch(), rend::test::criticalStretch(m));

    Lattice lattice = generateLattice(p.sheet);
    BondFamilies shared = buildBondFamilies(lattice.positions, 1.5 * p.sheet.dx);
    const std::vector<double> volumes(lattice.positions.size(),
                                      lattice.particleArea * p.sheet.thickness);
    PeridynamicBonds solver(p, lattice, shared, lattice.positions, volumes);
    DamageState damage(shared, lattice.triangles);
    solver.bind(shared, damage);
    std::vector<Eigen::Vector3d> x = lattice.positions, v(x.size(), Eigen::Vector3d::Zero()), f;
    const double etaC = solver.criticalStretch();
    for (auto& xi : x) xi.x() *= 1.0 + 1.01 * etaC;  // every x-leaning bond past eta_c
    f.resize(x.size());
    f = solver.advanceAt(x, v, 1e-3);
    const auto broken = std::count(damage.bondAlive().begin(), damage.bondAlive().end(), 0);
    EXPECT_GT(broken, 0);
    EXPECT_EQ(std::size_t(broken), 2 * damage.brokenBondCount()) << "both copies break";
    for (auto& xi : x) xi.x() /= 1.0 + 1.01 * etaC;  // back to rest: nothing heals
    f = solver.advanceAt(x, v, 1e-3);
    EXPECT_EQ(std::count(damage.bondAlive().begin(), damage.bondAlive().end(), 0), broken);

    p.material.fractureEnergy.reset();
    p.material.law = BondLawKind::PowerLaw;
    PeridynamicBonds rubber(p, lattice, shared, lattice.positions, volumes);
    DamageState intact(shared, lattice.triangles);
    rubber.bind(shared, intact);
    x = lattice.positions;
    for (auto& xi : x) xi *= 0.8;
    f = rubber.advanceAt(x, v, 1e-3);
    EXPECT_NEAR(rubber.stiffening(), rubber.law().powerLawStiffening(-0.2), 1e-9)
        << "the most compressed bond sets the sub-steps";
    p.material.stiffnessLoss = 5.0;  // dissolved past theta = 0.2
    PeridynamicBonds dissolved(p, lattice, shared, lattice.positions, volumes);
    dissolved.bind(shared, intact);
    for (auto& xi : x) xi *= 0.625;  // 50% compression
    std::vector<double> theta(x.size(), 0.25);
    theta[0] =
        0.05;  // theta-bar 0.15 on its bonds: a quarter of the stiffness, and only they count
    std::vector<Eigen::Vector3d> force;
    dissolved.advance({x, v, theta, 1e-3}, *dissolved.makeWorkspace(), force);
    const double quarter = 0.25 * dissolved.law().powerLawStiffening(-0.5);
    ASSERT_GT(quarter, 2.0);
    EXPECT_NEAR(dissolved.stiffening(), quarter, 1e-9 * quarter)
        << "a dissolved bond, squashed but carrying no force, does not cut the step";

    p.material.law = BondLawKind::Elastoplastic;
    p.material.yieldStrain = 0.01;
    Membrane foil(p);
    for (int i = 0; i < foil.particleCount(); ++i)
        foil.positions()[i] = 1.03 * foil.restPositions()[i];
    foil.step();
    foil.updateDamage();
    const double gamma = rend::test::bondsOf(foil).law().strengthLeft({0.03});
    EXPECT_LT(gamma, 1.0);
    const int centre = foil.nearestParticle({0, 0});
    EXPECT_NEAR(foil.damage()[centre], 1.0 - gamma, 0.02)
        << "every bond yielded to about 3%: damage is 1 - gamma";
}

TEST(Solvers, UniaxialStressPatchIsInEquilibriumAndCarriesE) {
    // Affine uniaxial stress along x (strain e, -nu e across): every particle away from the two
    // ends must be force-free, and the right half's force is E e h H, H the height of the
    // triangulated sheet. The FEM and the two-parameter springs hold this for any nu; a
    // central-spring network only at nu = 1/3 (Van Gelder then equals Lloyd's sqrt(3)/4 E t per
    // triangle). The SPH gives every particle its whole cell, so it carries E e h (H + one row):
    // 1.045 here.
    struct Case {
        std::string solver;
        double nu;
        bool exact;
    };
    const Case cases[] = {{"fem_cst", 0.3, true},
                          {"fem_cst", 0.45, true},
                          {"mass_spring_vg", 1.0 / 3.0, true},
                          {"mass_spring_vg", 0.3, false},
                          {"mass_spring_tp", 1.0 / 3.0, true},
                          {"mass_spring_tp", 0.3, true},
                          {"sph", 0.3, false}};
    const double e = 1e-6;
    for (const Case& c : cases) {
        Membrane m(sheet(c.solver, c.nu));
        double xMin = 1e9, xMax = -1e9, yMin = 1e9, yMax = -1e9;
        for (const auto& x : m.restPositions()) {
            xMin = std::min(xMin, x.x()), xMax = std::max(xMax, x.x());
            yMin = std::min(yMin, x.y()), yMax = std::max(yMax, x.y());
        }
        for (int i = 0; i < m.particleCount(); ++i) {
            const Eigen::Vector3d& x0 = m.restPositions()[i];
            m.positions()[i] = {x0.x() * (1 + e), x0.y() * (1 - c.nu * e), 0.0};
        }
        std::vector<Eigen::Vector3d> f;
        m.computeForces(f);
        const double dx = 0.02;
        double inside = 0.0, right = 0.0;
        for (int i = 0; i < m.particleCount(); ++i) {
            const double x = m.restPositions()[i].x();
            if (x > 0.0) right += f[i].x();  // what the right half carries, wherever it lands
            if (std::abs(x) < xMax - 2.5 * dx) inside = std::max(inside, f[i].norm());
        }
        const double expected = 2e4 * e * 1e-3 * (yMax - yMin);
        std::printf(
            "%-15s nu = %.3f: right half's force / (E e h H) = %.6f, largest inner force / it "
            "= %.2e\n",
            c.solver.c_str(), c.nu, -right / expected, inside / expected);
        if (c.exact) {
            EXPECT_NEAR(-right / expected, 1.0, 1e-5) << c.solver.c_str() << " " << c.nu;
            EXPECT_LT(inside / expected, 1e-5) << c.solver.c_str() << " " << c.nu;
        }
        if (c.solver == "sph") {
            const double cells = (yMax - yMin + dx * std::sqrt(3.0) / 2) / (yMax - yMin);
            EXPECT_NEAR(-right / expected, cells, 0.01 * cells) << "sph";
            EXPECT_LT(inside / expected, 1e-4) << "sph";
        }
    }
}

TEST(Solvers, StableStepBoundsTheHighestFrequency) {
    // Power iteration on M^-1 K (K from finite differences of the forces at rest): the
    // explicit schemes need omega_max dt <= 2, and the bound must hold without being far off.
    for (std::string s : kSolvers) {
        Membrane m(sheet(s, 0.3, 0.2, 0.2));
        const int n = m.particleCount();
        std::vector<Eigen::Vector3d> v(n), f;
        for (int i = 0; i < n; ++i)
            v[i] = Eigen::Vector3d(uniformFromHash(3, 3 * i) - 0.5,
                                   uniformFromHash(3, 3 * i + 1) - 0.5, 0.0);
        double lambda = 0.0;
        for (int it = 0; it < 400; ++it) {
            double norm = 0.0;
            for (const auto& x : v) norm = std::max(norm, x.norm());
            const double h = 1e-9 / norm;
            for (int i = 0; i < n; ++i) m.positions()[i] = m.restPositions()[i] + h * v[i];
            m.computeForces(f);
            double num = 0.0, den = 0.0;
            for (int i = 0; i < n; ++i) {
                const Eigen::Vector3d w = -f[i] / (h * m.masses()[i]);
                num += w.dot(v[i]) * m.masses()[i];
                den += v[i].squaredNorm() * m.masses()[i];
                v[i] = w;
            }
            lambda = num / den;
            double size = 0.0;
            for (const auto& x : v) size = std::max(size, x.norm());
            for (auto& x : v) x /= size;
        }
        const double omegaDt = std::sqrt(lambda) * m.stableTimeStep();
        std::printf("%-15s omega_max * stable dt = %.3f (stable below 2)\n", s.c_str(), omegaDt);
        EXPECT_LE(omegaDt, 2.0) << s.c_str();
        EXPECT_GT(omegaDt, 0.5) << s.c_str() << ": the bound is needlessly small";
    }
}

TEST(Solvers, EverySolverRunsAStretchWithTheSameBoundariesAndStaysFinite) {
    for (std::string s : kSolvers) {
        MembraneParams p = sheet(s, 0.3);
        BoundaryCondition left, rightEdge;
        left.kind = BoundaryKind::Pinned;
        left.region.max.x() = -0.19;
        rightEdge.kind = BoundaryKind::Velocity;
        rightEdge.region.min.x() = 0.19;
        rightEdge.velocity = {0.02, 0, 0};
        p.boundaries = {left, rightEdge};
        p.damping = 2.0;
        Membrane m(p);
        for (int k = 0; k < 2000; ++k) m.step();
        double xMax = -1e9;
        for (const auto& x : m.positions()) {
            ASSERT_TRUE(x.allFinite()) << s.c_str();
            xMax = std::max(xMax, x.x());
        }
        EXPECT_NEAR(xMax, 0.2 + 0.02 * m.time(), 1e-9) << s.c_str() << ": the grip moved";
        EXPECT_GT(m.strainEnergy(), 0.0) << s.c_str();
    }
}

TEST(Solvers, SpringsAndElementsBreakPastTheCriticalStrainAndNeverHeal) {
    for (std::string s : {"fem_cst", "mass_spring_vg", "mass_spring_tp"}) {
        MembraneParams p = sheet(s, 1.0 / 3.0, 0.2, 0.2);
        p.material.fractureEnergy = 5.0;
        const double spring = std::sqrt(2 * 5.0 / (std::sqrt(3.0) * 2e4 * 0.02));
        ASSERT_NEAR(springCriticalStrain(p), spring, 1e-15);
        // Elements and two-parameter triangles go in bands: sqrt(2 (1 - nu^2)) = 4/3 of it.
        const bool band = s != "mass_spring_vg";
        const double critical = band ? bandCriticalStrain(p) : spring;
        if (band) {
            ASSERT_NEAR(critical, 4.0 / 3.0 * spring, 1e-15);
        }
        for (double factor : {0.98, 1.02}) {
            Membrane m(p);
            // A uniform isotropic stretch: every spring (and the principal strain of every
            // element) at factor * critical.
            for (int i = 0; i < m.particleCount(); ++i)
                m.positions()[i] = (1 + factor * critical) * m.restPositions()[i];
            m.step();
            const std::size_t broken = m.brokenBondCount();
            if (factor < 1) {
                EXPECT_EQ(broken, 0u) << s.c_str();
                continue;
            }
            EXPECT_EQ(broken, m.bondCount()) << s.c_str() << ": every edge came apart";
            for (int i = 0; i < m.particleCount(); ++i) m.positions()[i] = m.restPositions()[i];
            for (int k = 0; k < 10; ++k) m.step();
            EXPECT_EQ(m.brokenBondCount(), broken) << s.c_str() << ": damage never heals";
            m.updateDamage();
            for (double d : m.damage()) EXPECT_DOUBLE_EQ(d, 1.0) << s.c_str();
            const FrameView v = m.view(1);
            ASSERT_EQ(v.keptTriangles.size(), m.lattice().triangles.size());
            for (auto kept : v.keptTriangles) EXPECT_EQ(kept, 0) << s.c_str();
            // Only the FEM removes triangles (erodes elements); springs break edges.
            EXPECT_EQ(m.damageState().removedTriangleCount(),
                      s == "fem_cst" ? m.lattice().triangles.size() : 0u)
                << s.c_str();
        }
    }
}

TEST(Solvers, SpringsAlongANotchAreCutAndALoadedNotchedSheetTearsFinitely) {
    // The mass-spring solvers cut exactly the springs whose bonds the notch crosses (the
    // peridynamic notch logic decides, so the FrameView and the springs agree), carry nothing
    // across the cut, and under load break more springs without losing finiteness.
    for (std::string s : {"mass_spring_vg", "mass_spring_tp"}) {
        MembraneParams p = sheet(s, 1.0 / 3.0, 0.4, 0.4);
        p.material.fractureEnergy = 0.05;
        p.notches = {Notch{{{-0.25, 0.0085}, {0.0, 0.0085}}}};
        Membrane m(p);
        const std::size_t notched = m.brokenBondCount();
        EXPECT_EQ(notched, m.notchedBondCount()) << s.c_str();
        EXPECT_GE(notched, 20u) << s.c_str() << ": two springs per dx of notch";
        // Pull the two halves apart rigidly: the cut springs must not pull back.
        for (int i = 0; i < m.particleCount(); ++i) {
            const Eigen::Vector3d& x0 = m.restPositions()[i];
            m.positions()[i] = x0 + Eigen::Vector3d(0, x0.y() > 0.0085 ? 0.01 : 0.0, 0);
        }
        std::vector<Eigen::Vector3d> f;
        m.computeForces(f);
        for (int i = 0; i < m.particleCount(); ++i) {
            if (m.restPositions()[i].x() < -0.05) {  // far from the tip, across the cut only
                EXPECT_LT(f[i].norm(), 1e-12) << s.c_str() << " particle " << i;
            }
        }

        BoundaryCondition top, bottom;
        top.kind = bottom.kind = BoundaryKind::Velocity;
        top.region.min.y() = 0.19;
        bottom.region.max.y() = -0.19;
        top.velocity = {0, 0.05, 0};
        bottom.velocity = {0, -0.05, 0};
        p.boundaries = {top, bottom};
        p.damping = 5.0;
        Membrane loaded(p);
        while (loaded.time() < 0.5) loaded.step();
        EXPECT_GT(loaded.brokenBondCount(), notched) << s.c_str();
        for (const auto& x : loaded.positions()) ASSERT_TRUE(x.allFinite()) << s.c_str();
    }
}

TEST(Solvers, ThermalStrainWithEveryCoupledSolverAndBondLawsWithVanGelder) {
    // Uniform theta = 1 with alpha = 0.01: the free sheet settles 1% larger, exactly, with
    // every solver that couples to theta.
    for (std::string s : kSolvers) {
        MembraneParams p = sheet(s, 0.3, 0.2, 0.2);
        p.material.expansion = 0.01;
        p.diffusion.initial = 1.0;
        p.damping = 20.0;
        Membrane warm(p);
        for (int k = 0; k < 4000; ++k) warm.step();
        const int a = warm.nearestParticle({-0.1, 0}), b = warm.nearestParticle({0.1, 0});
        const double strain = (warm.positions()[b] - warm.positions()[a]).norm() /
                                  (warm.restPositions()[b] - warm.restPositions()[a]).norm() -
                              1.0;
        EXPECT_NEAR(strain, 0.01, 1e-6) << s.c_str() << ": free thermal expansion";
    }

    // Elastoplastic springs keep a permanent set once loaded past the yield strain (eq. 20).
    MembraneParams p = sheet("mass_spring_vg", 1.0 / 3.0, 0.2, 0.2);
    p.material.law = BondLawKind::Elastoplastic;
    p.material.yieldStrain = 0.01;
    p.material.softening = 0.5;
    Membrane m(p);
    for (int i = 0; i < m.particleCount(); ++i) m.positions()[i] = 1.03 * m.restPositions()[i];
    m.step();  // records the largest strain of every spring
    for (int i = 0; i < m.particleCount(); ++i) m.positions()[i] = m.restPositions()[i];
    std::vector<Eigen::Vector3d> f;
    m.computeForces(f);
    EXPECT_GT(maxNorm(f), 0.0) << "at the rest shape the yielded springs push: a permanent set";
    EXPECT_GT(m.strainEnergy(), 0.0);
}

TEST(Solvers, AFemNotchRemovesTheElementsItCuts) {
    // Every element with a side the notch crosses is removed (a gap one element wide); the
    // FrameView drops exactly those triangles and the halves come apart along the notch.
    MembraneParams p = sheet("fem_cst", 0.3, 0.4, 0.4);
    p.notches = {Notch{{{-0.25, 0.0085}, {0.0, 0.0085}}}};
    Membrane m(p);
    const FrameView v = m.view(1);
    std::size_t removed = 0;
    const std::vector<std::uint8_t>& alive = m.damageState().triangleAlive();
    for (std::size_t t = 0; t < alive.size(); ++t) {
        if (alive[t]) continue;
        EXPECT_FALSE(v.keptTriangles[t]);
        ++removed;
        bool cutSide = false;
        for (int e = 0; e < 3; ++e) {
            const int a = v.restTriangles[t][e], b = v.restTriangles[t][(e + 1) % 3];
            cutSide = cutSide || !v.bondAlive[v.findBond(a, b)];
        }
        EXPECT_TRUE(cutSide) << "triangle " << t << " was removed without a cut side";
    }
    EXPECT_GE(removed, m.notchedBondCount()) << "each cut side takes its elements";
    for (int i = 0; i < m.particleCount(); ++i) {  // pull the halves apart rigidly
        const Eigen::Vector3d& x0 = m.restPositions()[i];
        m.positions()[i] = x0 + Eigen::Vector3d(0, x0.y() > 0.0085 ? 0.01 : 0.0, 0);
    }
    std::vector<Eigen::Vector3d> f;
    m.computeForces(f);
    for (int i = 0; i < m.particleCount(); ++i) {
        if (m.restPositions()[i].x() < -0.05) {  // far from the tip, across the cut only
            EXPECT_LT(f[i].norm(), 1e-12) << i;
        }
    }
}

TEST(Solvers, OneAndTwoThreadsGiveIdenticalBitsWithEverySolver) {
    // Each solver computes per element (or particle) in parallel and sums per particle in a
    // fixed order, so the thread count cannot change a bit, fracture included.
    for (std::string s : kSolvers) {
        MembraneParams p = sheet(s, 0.3, 1.0, 1.0);
        p.sheet.perturbationAmplitude = 1e-4;
        p.material.fractureEnergy = 0.02;
        p.boundaries = support::pullingGrips();
        SCOPED_TRACE(s.c_str());
        const std::size_t broken = support::expectSameBitsWithOneAndTwoThreads(p, 300);
        std::printf("%-15s 1 and 2 threads: identical bits, %zu broken bonds\n", s.c_str(), broken);
    }
}

TEST(Solvers, AnSphNotchRemovesThePairsThatCrossIt) {
    // Pairs reach 2 dx, further than the bonds: the SPH cuts its own pairs along the notch,
    // so pulling the halves apart rigidly far from the tip costs nothing.
    MembraneParams p = sheet("sph", 0.3, 0.4, 0.4);
    p.notches = {Notch{{{-0.25, 0.0085}, {0.0, 0.0085}}}};
    Membrane m(p);
    for (int i = 0; i < m.particleCount(); ++i) {
        const Eigen::Vector3d& x0 = m.restPositions()[i];
        m.positions()[i] = x0 + Eigen::Vector3d(0, x0.y() > 0.0085 ? 0.01 : 0.0, 0);
    }
    std::vector<Eigen::Vector3d> f;
    m.computeForces(f);
    double far = 0.0, near = 0.0;
    for (int i = 0; i < m.particleCount(); ++i)
        (m.restPositions()[i].x() < -0.08 ? far : near) =
            std::max(m.restPositions()[i].x() < -0.08 ? far : near, f[i].norm());
    EXPECT_LT(far, 1e-12) << "no pair bridges the notch";
    EXPECT_GT(near, 1e-6) << "beyond the tip the sheet is whole";
}

TEST(Damage, AnErodedElementTakesNoPressureThoughItsSidesAreIntact) {
    const MembraneParams p = rend::test::erodingSheet(10.0);
    Membrane m(p);
    const int t = rend::test::erodeOneElement(m, p);
    const DamageState& damage = m.damageState();
    ASSERT_EQ(damage.removedTriangleCount(), 1u);
    ASSERT_FALSE(damage.triangleAlive()[t]);
    for (int e : damage.triangleEdges(t)) ASSERT_TRUE(damage.edgeIntact(e)) << "neighbours hold it";
    EXPECT_FALSE(m.view(1).keptTriangles[t]);
    support::expectConsistentDamage(m);

    // Internal forces sum to zero, so one more step gains dt times the pressure on the kept
    // triangles at x^n (symplectic Euler, no gravity, no grips).
    const std::vector<Eigen::Vector3d> x = std::as_const(m).positions();
    const Eigen::Vector3d before = m.totalMomentum();
    m.step();
    ASSERT_EQ(damage.removedTriangleCount(), 1u);
    Eigen::Vector3d kept = Eigen::Vector3d::Zero(), all = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < m.lattice().triangles.size(); ++k) {
        const auto [a, b, c] = m.lattice().triangles[k];
        const Eigen::Vector3d push = p.pressure * 0.5 * (x[b] - x[a]).cross(x[c] - x[a]);
        all += push;
        if (damage.keptTriangles()[k]) kept += push;
    }
    const Eigen::Vector3d gained = (m.totalMomentum() - before) / *p.time.dt;
    EXPECT_NEAR((gained - kept).norm(), 0.0, 1e-9 * kept.norm());
    EXPECT_GT((all - kept).norm(), 1e-3 * kept.norm()) << "the element would have taken a share";
}

TEST(Damage, EverySolverBreaksOnlyThroughTheDamageState) {
    // A notched sheet pulled apart: whatever each solver breaks (bonds, springs, elements,
    // pairs) shows in the one DamageState, consistently, and 1 and 2 threads agree on it.
    for (std::string s : kSolvers) {
        MembraneParams p = sheet(s, 0.3, 1.0, 1.0);
        p.material.fractureEnergy = 0.02;
        p.boundaries = support::pullingGrips();
        p.notches = {Notch{{{-0.2, 0.011}, {0.0, 0.011}}}};
        SCOPED_TRACE(s.c_str());
        Membrane m(p);
        support::expectConsistentDamage(m);
        const std::size_t notched = m.brokenBondCount();
        EXPECT_GT(notched, 0u);
        for (int k = 0; k < 300; ++k) m.step();
        support::expectConsistentDamage(m);
        EXPECT_GT(m.brokenBondCount(), notched) << "the crack grew";
    }
}

TEST(SolverRegistry, NamesEachSolverOnceAndEveryFactoryBuildsARunningMembrane) {
    std::set<std::string_view> names;
    for (const SolverEntry& entry : solverRegistry()) {
        EXPECT_TRUE(names.insert(entry.name).second) << entry.name << " twice";
        EXPECT_EQ(findSolver(entry.name), &entry);
        MembraneParams p = sheet(std::string(entry.name), 0.3, 0.12, 0.12);
        Membrane m(p);
        EXPECT_NO_THROW(m.step()) << entry.name;
    }
    EXPECT_EQ(solverRegistry().front().name, MembraneParams{}.solver) << "the default first";
    EXPECT_EQ(findSolver("xpbd"), nullptr);
    EXPECT_THROW(solverEntry("xpbd"), std::invalid_argument);
}

TEST(SolverRegistry, SaysWhatASolverDoesNotTake) {
    MembraneParams p = sheet("sph", 0.3);
    p.material.law = BondLawKind::PowerLaw;
    p.material.surfaceCorrection = true;
    EXPECT_EQ(unsupportedFeatures(solverEntry("sph"), p),
              "a bond law other than linear and surface_correction");
    EXPECT_EQ(unsupportedFeatures(solverEntry("peridynamic"), p), "");
}

TEST(SolverRegistry, TheReadmeSolverTableIsTheRegistrys) {
    std::ifstream in(std::string(REND_SOURCE_DIR) + "/README.md");
    std::stringstream readme;
    readme << in.rdbuf();
    const std::string table = solverTableMarkdown();
    EXPECT_NE(readme.str().find(table), std::string::npos)
        << "README \"Solvers\" must hold the registry's table:\n"
        << table;
}
