// The FEM CST membrane with the membrane paper's non-linear bond laws (seeds/000, eqs. 19 and
// 20): under uniaxial stress an element must follow the bond's curve E f(eta)/c, the forces must
// be the gradient of the energy, yielding must leave the 1D law's permanent strain.

#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <utility>

#include "sim/BondLaw.h"
#include "sim/FemCst.h"
#include "sim/Lattice.h"
#include "sim/Membrane.h"
#include "sim/Random.h"
#include "tests/sim/ThreadCheck.h"

using namespace rend::sim;

namespace {

constexpr double kE = 2e4, kNu = 0.3, kThickness = 1e-3;

MaterialParams powerLaw(double ratio, double exponent) {
    MaterialParams m;
    m.youngsModulus = kE;
    m.poissonRatio = kNu;
    m.law = BondLawKind::PowerLaw;
    m.powerLawRatio = ratio;
    m.powerLawExponent = exponent;
    return m;
}

MaterialParams elastoplastic(double yieldStrain, double softening) {
    MaterialParams m;
    m.youngsModulus = kE;
    m.poissonRatio = kNu;
    m.law = BondLawKind::Elastoplastic;
    m.yieldStrain = yieldStrain;
    m.softening = softening;
    return m;
}

SheetParams patch(double size = 0.2) {
    SheetParams s;
    s.size = {size, size};
    s.dx = 0.02;
    s.thickness = kThickness;
    return s;
}

double maxNorm(const std::vector<Eigen::Vector3d>& f) {
    double m = 0.0;
    for (const auto& v : f) m = std::max(m, v.norm());
    return m;
}

/// A patch of elements stretched by (1 + eta) along x, its lateral stretch found by bisection so
/// that the top half carries no net force (uniaxial stress). Reports the nominal stress: the
/// force the right half carries over the rest cross-section h H.
struct UniaxialPatch {
    Lattice lattice;
    FemCst fem;
    double height = 0.0;
    std::vector<Eigen::Vector3d> x, f;

    UniaxialPatch(const MaterialParams& m)
        : lattice(generateLattice(patch())),
          fem(lattice, m, kThickness, std::numeric_limits<double>::infinity()) {
        double yMin = 1e9, yMax = -1e9;
        for (const auto& p : lattice.positions)
            yMin = std::min(yMin, p.y()), yMax = std::max(yMax, p.y());
        height = yMax - yMin;
        x = lattice.positions;
        f.resize(x.size());
    }
    void place(double eta, double lateral) {
        for (std::size_t i = 0; i < x.size(); ++i)
            x[i] = {lattice.positions[i].x() * (1 + eta), lattice.positions[i].y() * lateral, 0};
    }
    /// Net y force on the top half at lateral stretch `lateral` (decreasing in it).
    double lateralForce(double eta, double lateral) {
        place(eta, lateral);
        f = fem.forcesAt(x);
        double sum = 0.0;
        for (std::size_t i = 0; i < x.size(); ++i)
            if (lattice.positions[i].y() > 0.0) sum += f[i].y();
        return sum;
    }
    /// Nominal stress along x under uniaxial stress at strain eta (history left as it is).
    double stress(double eta) {
        double low = 0.3, high = 2.0;
        for (int it = 0; it < 80; ++it) {
            const double mid = 0.5 * (low + high);
            (lateralForce(eta, mid) > 0.0 ? low : high) = mid;
        }
        lateralForce(eta, 0.5 * (low + high));
        double right = 0.0;
        for (std::size_t i = 0; i < x.size(); ++i)
            if (lattice.positions[i].x() > 0.0) right += f[i].x();
        return -right / (kThickness * height);
    }
};

void jitter(std::vector<Eigen::Vector3d>& x, double amplitude, std::uint64_t seed) {
    for (int i = 0; i < int(x.size()); ++i)
        for (int a = 0; a < 3; ++a)
            x[i][a] += amplitude * (2.0 * uniformFromHash(seed, std::uint64_t(3 * i + a)) - 1.0);
}

}  // namespace

TEST(FemLaws, UniaxialStressFollowsThePowerLawCurve) {
    // The bond's nominal stress E f(eta)/c (eq. 19) at every strain, tension and compression,
    // for the rubber preset (n = 2), Membrane's default (n = 4) and a fractional exponent.
    struct Case {
        double ratio, exponent, lowest, highest;
    };
    for (const Case& c :
         {Case{-0.05, 2.0, -0.4, 1.0}, Case{-0.1, 4.0, -0.3, 0.3}, Case{-0.05, 2.5, -0.3, 0.5}}) {
        const MaterialParams m = powerLaw(c.ratio, c.exponent);
        const BondLaw law = BondLaw::fromMaterial(m, 1.0);
        UniaxialPatch p(m);
        double worst = 0.0;
        for (int k = 0; k <= 14; ++k) {
            const double eta = c.lowest + (c.highest - c.lowest) * k / 14.0;
            const double expected = kE * law.force(eta);
            worst = std::max(
                worst, std::abs(p.stress(eta) - expected) / (kE * std::max(std::abs(eta), 0.01)));
        }
        std::printf(
            "power law n = %.1f, c*/c = %.2f: worst |stress - E f/c| / (E max(|eta|, 0.01)) = "
            "%.1e\n",
            c.exponent, c.ratio, worst);
        EXPECT_LT(worst, 1e-8) << "n = " << c.exponent;
        // And the curve is not the linear one: the law bends it.
        EXPECT_GT(std::abs(p.stress(c.highest) - kE * c.highest), 1e-3 * kE * c.highest);
    }
}

TEST(FemLaws, SmallStrainMatchesTheLinearElement) {
    // At 1e-6 strain every law carries what the St. Venant-Kirchhoff element carries.
    const double eta = 1e-6;
    MaterialParams linear = powerLaw(0.0, 2.0);
    linear.law = BondLawKind::Linear;
    UniaxialPatch reference(linear);
    const double expected = reference.stress(eta);
    EXPECT_NEAR(expected, kE * eta, 1e-5 * kE * eta) << "SVK: E eta to first order";
    for (const MaterialParams& m :
         {powerLaw(-0.05, 2.0), powerLaw(-0.1, 4.0), elastoplastic(0.01, 1.0)}) {
        UniaxialPatch p(m);
        EXPECT_NEAR(p.stress(eta), expected, 1e-5 * expected) << int(m.law);
    }
}

TEST(FemLaws, ElastoplasticLoadingSoftensAndUnloadsToThePermanentStrain) {
    // Loaded along eq. 20's path, the stress is E f(eta)/c; unloaded, it falls with slope E
    // to zero at the bond's permanent strain eta_max - f(eta_max)/c, and the history stays.
    const MaterialParams m = elastoplastic(0.02, 0.5);
    const BondLaw law = BondLaw::fromMaterial(m, 1.0);
    UniaxialPatch p(m);
    const double top = 0.08;
    double worst = 0.0;
    for (int k = 1; k <= 40; ++k) {
        const double eta = top * k / 40.0;
        p.place(eta, 1.0);
        p.fem.fractureAt(p.x);  // the history step, at the stretch along x
        const double expected = kE * law.force(eta, {eta});
        worst = std::max(worst, std::abs(p.stress(eta) - expected) / (kE * law.yieldStrain));
    }
    std::printf("elastoplastic loading: worst |stress - E f/c| / (E eta0) = %.1e\n", worst);
    EXPECT_LT(worst, 1e-8);
    const double gamma = law.strengthLeft({top});
    for (int t = 0; t < p.fem.elementCount(); ++t) {
        ASSERT_NEAR(p.fem.maxStrain(t), top, 1e-9) << t;
        ASSERT_NEAR(p.fem.strengthLeft(t), gamma, 1e-8) << t;
    }
    EXPECT_LT(gamma, 0.5) << "softened well past the yield strain";

    // Unload: the slope is E, and the stress vanishes at the permanent strain.
    const double permanent = law.plasticStrain({top});
    double low = 0.0, high = top;
    for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (low + high);
        p.place(mid, 1.0);
        p.fem.fractureAt(p.x);  // unloading must not yield
        (p.stress(mid) > 0.0 ? high : low) = mid;
    }
    std::printf("permanent strain: FEM %.9f, 1D law %.9f\n", 0.5 * (low + high), permanent);
    EXPECT_NEAR(0.5 * (low + high), permanent, 1e-9);
    const double middle = 0.5 * (permanent + top);
    EXPECT_NEAR(p.stress(middle), kE * (middle - permanent), 1e-8 * kE * top) << "slope E";
    for (int t = 0; t < p.fem.elementCount(); ++t)
        ASSERT_NEAR(p.fem.maxStrain(t), top, 1e-9) << "unloading left the history alone";
}

TEST(FemLaws, ForcesAreMinusTheGradientOfTheStrainEnergy) {
    // Large strains (a 20% stretch, 15% squeeze and jitter) so the laws' non-linear parts
    // count; the elastoplastic element at a yielded history.
    const MaterialParams laws[] = {powerLaw(-0.05, 2.0), powerLaw(-0.1, 4.0), powerLaw(-0.05, 2.5),
                                   elastoplastic(0.02, 0.5)};
    for (const MaterialParams& m : laws) {
        const Lattice lattice = generateLattice(patch(0.12));
        FemCst fem(lattice, m, kThickness, std::numeric_limits<double>::infinity());
        std::vector<Eigen::Vector3d> x = lattice.positions, f(x.size());
        for (auto& p : x) p = {1.2 * p.x(), 0.85 * p.y(), 0.0};
        jitter(x, 2e-3, 9);
        fem.fractureAt(x);  // the elastoplastic element yields here
        jitter(x, 2e-3, 10);
        f = fem.forcesAt(x);
        const double h = 1e-7;
        double worst = 0.0;
        for (int i = 0; i < int(x.size()); ++i)
            for (int a = 0; a < 3; ++a) {
                const double keep = x[i][a];
                x[i][a] = keep + h;
                const double up = fem.energyAt(x);
                x[i][a] = keep - h;
                const double down = fem.energyAt(x);
                x[i][a] = keep;
                worst = std::max(worst, std::abs(-(up - down) / (2 * h) - f[i][a]));
            }
        std::printf("law %d: worst |F + dW/dx| / max |F| = %.1e\n", int(m.law), worst / maxNorm(f));
        EXPECT_LT(worst, 1e-6 * maxNorm(f)) << int(m.law);
        if (m.law == BondLawKind::Elastoplastic) {
            double yielded = 0.0;
            for (int t = 0; t < fem.elementCount(); ++t)
                yielded = std::max(yielded, fem.maxStrain(t));
            EXPECT_GT(yielded, 0.1) << "the test must reach the softening branch";
        }
    }
}

TEST(FemLaws, RigidMotionGivesZeroForce) {
    const MaterialParams laws[] = {powerLaw(-0.05, 2.0), elastoplastic(0.02, 0.5)};
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    const Eigen::Vector3d shift(0.3, -1.0, 2.0);
    for (const MaterialParams& m : laws) {
        const Lattice lattice = generateLattice(patch());
        FemCst fem(lattice, m, kThickness, std::numeric_limits<double>::infinity());
        std::vector<Eigen::Vector3d> x = lattice.positions, before(x.size()), after(x.size());
        for (auto& p : x) p *= 1.05;
        jitter(x, 2e-3, 5);
        fem.fractureAt(x);  // a yielded history for the elastoplastic law
        before = fem.forcesAt(x);
        for (auto& p : x) p = R * p + shift;
        after = fem.forcesAt(x);
        double worst = 0.0;
        Eigen::Vector3d total = Eigen::Vector3d::Zero();
        for (std::size_t i = 0; i < x.size(); ++i) {
            worst = std::max(worst, (after[i] - R * before[i]).norm());
            total += before[i];
        }
        EXPECT_LT(worst, 1e-10 * maxNorm(before)) << int(m.law) << ": forces turn with the body";
        EXPECT_LT(total.norm(), 1e-12 * maxNorm(before) * x.size()) << int(m.law);

        FemCst fresh(lattice, m, kThickness, std::numeric_limits<double>::infinity());
        for (std::size_t i = 0; i < x.size(); ++i) x[i] = R * lattice.positions[i] + shift;
        after = fresh.forcesAt(x);
        EXPECT_LT(maxNorm(after), 1e-9 * maxNorm(before)) << int(m.law) << ": rest, moved";
    }
}

TEST(FemLaws, PowerLawStiffensInCompressionAndLooksAhead) {
    const MaterialParams m = powerLaw(-0.05, 2.0);
    const BondLaw law = BondLaw::fromMaterial(m, 1.0);
    const Lattice lattice = generateLattice(patch());
    FemCst fem(lattice, m, kThickness, std::numeric_limits<double>::infinity());
    std::vector<Eigen::Vector3d> x(lattice.positions.size()), v(x.size(), Eigen::Vector3d::Zero()),
        f(x.size());
    auto scaled = [&](double sx, double sy) {
        for (std::size_t i = 0; i < x.size(); ++i)
            x[i] = {sx * lattice.positions[i].x(), sy * lattice.positions[i].y(), 0.0};
    };
    scaled(1.2, 1.1);
    f = fem.advanceAt(x, v, 1e-3);
    EXPECT_EQ(fem.stiffening(), 1.0) << "tension does not stiffen";
    scaled(1.0, 0.7);
    f = fem.advanceAt(x, v, 1e-3);
    std::printf("power law at 30%% compression: stiffening %.3f\n", fem.stiffening());
    EXPECT_GT(fem.stiffening(), 1.5);
    EXPECT_NEAR(fem.stiffening(), law.powerLawStiffening(-0.3), 1e-9);
    // Closing at 10/s along y: in dt = 0.01 the stretch will be 0.7 - 0.1.
    for (std::size_t i = 0; i < x.size(); ++i) v[i] = {0.0, -10.0 * lattice.positions[i].y(), 0.0};
    f = fem.advanceAt(x, v, 0.01);
    EXPECT_NEAR(fem.stiffening(), law.powerLawStiffening(-0.4), 1e-9);

    // Membrane cuts its steps when a power-law sheet is squeezed.
    MembraneParams p;
    p.solver = "fem_cst";
    p.sheet = patch();
    p.material = m;
    p.material.density = 5000;
    Membrane squeezed(p);
    for (int i = 0; i < squeezed.particleCount(); ++i)
        squeezed.positions()[i] = 0.7 * squeezed.restPositions()[i];
    squeezed.step();
    EXPECT_GT(squeezed.extraSubsteps(), 0);
}

TEST(FemLaws, ThermalStrainWithBothLaws) {
    // Uniform theta = 1, alpha = 0.01: the free sheet settles 1% larger with either law (the
    // yield strain is above the dynamic overshoot, which a softening law would keep).
    for (const MaterialParams& law : {powerLaw(-0.05, 2.0), elastoplastic(0.05, 1.0)}) {
        MembraneParams p;
        p.solver = "fem_cst";
        p.sheet = patch();
        p.material = law;
        p.material.density = 5000;
        p.material.expansion = 0.01;
        p.diffusion.initial = 1.0;
        p.damping = 20.0;
        Membrane warm(p);
        for (int k = 0; k < 4000; ++k) warm.step();
        const int a = warm.nearestParticle({-0.1, 0}), b = warm.nearestParticle({0.1, 0});
        const double strain = (warm.positions()[b] - warm.positions()[a]).norm() /
                                  (warm.restPositions()[b] - warm.restPositions()[a]).norm() -
                              1.0;
        EXPECT_NEAR(strain, 0.01, 1e-6) << int(law.law) << ": free thermal expansion";
    }
}

TEST(FemLaws, YieldedElementsFeedTheDamageField) {
    // A uniform 5% stretch past a 1% yield strain: every bond's strength left, hence every
    // particle's damage, is 1 - gamma(T) of eq. 27, with T the 5% reached.
    MembraneParams p;
    p.solver = "fem_cst";
    p.sheet = patch();
    p.material = elastoplastic(0.01, 0.5);
    p.material.density = 5000;
    Membrane m(p);
    ASSERT_TRUE(m.canDamage());
    for (int i = 0; i < m.particleCount(); ++i) m.positions()[i] = 1.05 * m.restPositions()[i];
    m.step();
    m.updateDamage();
    const double gamma = BondLaw::fromMaterial(p.material, 1.0).strengthLeft({0.05});
    const int centre = m.nearestParticle({0.0, 0.0});
    EXPECT_NEAR(m.damage()[centre], 1.0 - gamma, 1e-3);
    EXPECT_GT(m.damage()[centre], 0.5);
}

TEST(FemLaws, NotchedSheetsTearWithBothLaws) {
    // A notch cuts the elements; pulled apart, the sheet breaks more and stays finite.
    for (const MaterialParams& law : {powerLaw(-0.05, 2.0), elastoplastic(0.01, 0.5)}) {
        MembraneParams p;
        p.solver = "fem_cst";
        p.sheet = patch(0.4);
        p.material = law;
        p.material.density = 5000;
        p.material.fractureEnergy = 0.05;
        p.notches = {Notch{{{-0.25, 0.0085}, {0.0, 0.0085}}}};
        BoundaryCondition top, bottom;
        top.kind = bottom.kind = BoundaryKind::Velocity;
        top.region.min.y() = 0.19;
        bottom.region.max.y() = -0.19;
        top.velocity = {0, 0.05, 0};
        bottom.velocity = {0, -0.05, 0};
        p.boundaries = {top, bottom};
        p.damping = 5.0;
        Membrane m(p);
        const std::size_t notched = m.brokenBondCount();
        EXPECT_GT(notched, 0u);
        while (m.time() < 0.5) m.step();
        EXPECT_GT(m.brokenBondCount(), notched) << int(law.law);
        for (const auto& x : m.positions()) ASSERT_TRUE(x.allFinite()) << int(law.law);
    }
}

TEST(FemLaws, OneAndTwoThreadsGiveIdenticalBits) {
    for (const MaterialParams& law : {powerLaw(-0.05, 2.0), elastoplastic(0.01, 0.5)}) {
        MembraneParams p;
        p.solver = "fem_cst";
        p.sheet = patch(1.0);
        p.sheet.perturbationAmplitude = 1e-4;
        p.material = law;
        p.material.density = 5000;
        p.material.fractureEnergy = 0.02;
        p.boundaries = support::pullingGrips();
        const std::size_t broken = support::expectSameBitsWithOneAndTwoThreads(p, 300);
        std::printf("law %d: 1 and 2 threads identical, %zu broken bonds\n", int(law.law), broken);
    }
}
