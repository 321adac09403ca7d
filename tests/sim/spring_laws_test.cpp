// The bond laws of the membrane paper (seeds/000, eqs. 19-20) in the mass-spring solvers of
// seeds/003: Van Gelder's springs and the two-parameter (TP-MSS) triangles take the law's shape
// phi(eta) = f(eta)/c, see sim/MassSpring.h.

#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <tuple>
#include <utility>

#include "sim/MassSpring.h"
#include "sim/Membrane.h"
#include "sim/Random.h"
#include "tests/sim/ThreadCheck.h"

using namespace rend::sim;

namespace {

constexpr double kE = 2e4, kH = 1e-3;

MaterialParams powerLaw() {  // the rubber_film preset's shape
    MaterialParams m;
    m.youngsModulus = kE;
    m.law = BondLawKind::PowerLaw;
    m.powerLawRatio = -0.05;
    m.powerLawExponent = 2.0;
    return m;
}

MaterialParams elastoplastic(double softening) {  // foil_tear.toml's yield strain
    MaterialParams m;
    m.youngsModulus = kE;
    m.law = BondLawKind::Elastoplastic;
    m.yieldStrain = 0.06;
    m.softening = softening;
    return m;
}

Lattice patch(double size = 0.4) {
    SheetParams s;
    s.size = {size, size};
    s.dx = 0.02;
    return generateLattice(s);
}

const char* nameOf(SpringModel model) {
    return model == SpringModel::VanGelder ? "mass_spring_vg" : "mass_spring_tp";
}

double maxNorm(const std::vector<Eigen::Vector3d>& f) {
    double m = 0.0;
    for (const auto& v : f) m = std::max(m, v.norm());
    return m;
}

/// A homogeneous uniaxial stress along x: the sheet stretched by 1 + e along x and by 1 + ey
/// across, ey found by bisection so that no force crosses the midline y = 0 (sigma_yy = 0).
/// Every interior triangle then has the same strains, so the interior is in equilibrium and
/// the force across x = 0 is the sheet's tension. Returns it over E h H (H the lattice's
/// height): phi(e) for a sheet that follows the 1D law exactly.
struct Pull {
    double tension, lateral;
};
Pull uniaxial(const MassSpring& springs, const Lattice& lattice, double e) {
    const auto& x0 = lattice.positions;
    double yMin = 1e9, yMax = -1e9;
    for (const auto& p : x0) yMin = std::min(yMin, p.y()), yMax = std::max(yMax, p.y());
    std::vector<Eigen::Vector3d> x(x0.size()), f(x0.size());
    auto place = [&](double ey) {
        for (std::size_t i = 0; i < x0.size(); ++i)
            x[i] = {x0[i].x() * (1 + e), x0[i].y() * (1 + ey), 0.0};
        f = springs.forcesAt(x);
        double across = 0.0;  // what the lower half pulls the upper half with, along y
        for (std::size_t i = 0; i < x0.size(); ++i)
            if (x0[i].y() > 0.0) across += f[i].y();
        return across;
    };
    double lo = -0.45, hi = 0.45;  // stretching across (ey up) pulls the upper half back
    for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        (place(mid) > 0.0 ? lo : hi) = mid;
    }
    place(0.5 * (lo + hi));
    double right = 0.0;
    for (std::size_t i = 0; i < x0.size(); ++i)
        if (x0[i].x() > 0.0) right += f[i].x();
    return {-right / (kE * kH * (yMax - yMin)), 0.5 * (lo + hi)};
}

/// Records the history (yield) at the uniaxial state of the last uniaxial() call's strains.
void recordUniaxial(MassSpring& springs, const Lattice& lattice, double e, double ey) {
    std::vector<Eigen::Vector3d> x(lattice.positions.size()), v(x.size(), Eigen::Vector3d::Zero());
    std::vector<Eigen::Vector3d> f(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
        const Eigen::Vector3d& p = lattice.positions[i];
        x[i] = {p.x() * (1 + e), p.y() * (1 + ey), 0.0};
    }
    f = springs.advanceAt(x, v, 1e-3);
}

std::vector<Eigen::Vector3d> scaled(const Lattice& lattice, double s) {
    std::vector<Eigen::Vector3d> x = lattice.positions;
    for (auto& p : x) p *= s;
    return x;
}

}  // namespace

TEST(SpringLaws, TwoParameterUniaxialPullFollowsThePowerLawShape) {
    // Tension over E h H against phi(e) of eq. 19 (ratio -0.05, n = 2), from 30% compression
    // to 60% stretch. The linear TP itself is not linear at finite strain (its heights are
    // measured in the current triangle: 0.363 instead of 0.6 at e = 0.6), so the law's shape is
    // T_law / T_linear = phi(e)/e. The secant of each spring makes that exact along a lattice
    // row, where the diagonal springs carry nothing; VG at nu = 1/3 is exact outright.
    const Lattice lattice = patch();
    const MaterialParams m = powerLaw();
    MaterialParams linear = m;
    linear.law = BondLawKind::Linear;
    const BondLaw shape = BondLaw::fromMaterial(m, 1.0);
    const auto infinity = std::numeric_limits<double>::infinity();
    const MassSpring tp(lattice, SpringModel::TwoParameter, m, kH, infinity);
    const MassSpring tpLinear(lattice, SpringModel::TwoParameter, linear, kH, infinity);
    MaterialParams vgLaw = m;
    vgLaw.poissonRatio = 1.0 / 3.0;  // Van Gelder's exact nu
    const MassSpring vg(lattice, SpringModel::VanGelder, vgLaw, kH, infinity);
    double worstShape = 0.0, worstTp = 0.0, worstVg = 0.0;
    for (double e = -0.3; e <= 0.6 + 1e-9; e += 0.05) {
        if (std::abs(e) < 1e-9) continue;
        const double law = uniaxial(tp, lattice, e).tension;
        const double lin = uniaxial(tpLinear, lattice, e).tension;
        const double v = uniaxial(vg, lattice, e).tension;
        const double secant = shape.force(e) / e;
        worstShape = std::max(worstShape, std::abs(law / lin - secant) / secant);
        worstTp = std::max(worstTp, std::abs(law - shape.force(e)) / std::abs(shape.force(e)));
        worstVg = std::max(worstVg, std::abs(v - shape.force(e)) / std::abs(shape.force(e)));
        std::printf("e = %+.2f: phi %+.5f, TP %+.5f (linear TP %+.5f), VG %+.5f\n", e,
                    shape.force(e), law, lin, v);
    }
    std::printf(
        "power law: |T_tp/T_tp,linear - phi/e| / (phi/e) <= %.1e, |T_tp - phi| / phi <= "
        "%.3f, |T_vg - phi| / phi <= %.1e\n",
        worstShape, worstTp, worstVg);
    EXPECT_LT(worstShape, 1e-9);
    EXPECT_LT(worstVg, 1e-9);
    // Linear springs would miss the shape by far more than the tolerance: the test can fail.
    EXPECT_GT(std::abs(shape.force(0.6) - 0.6) / 0.6, 0.1);
    EXPECT_GT(std::abs(shape.force(-0.3) + 0.3) / 0.3, 0.1);
}

TEST(SpringLaws, TwoParameterUniaxialPullFollowsTheElastoplasticShape) {
    // Loading path of eq. 20 (eta0 = 0.06, beta = 1): linear to the yield strain, then the
    // exponential softening. Below eta0 the sheet is today's linear TP bit for bit; beyond, a
    // triangle is the linear TP about its plastic rest triangle, whose rows along the pull grow
    // by p while its heights shrink by ~p/3, so the sheet carries about
    // E h H (e - p) / ((1 + p)(1 + p/3)): 23% below f/c at e = 0.2 (p = 0.19), 5.5% of eta0.
    const Lattice lattice = patch();
    const MaterialParams m = elastoplastic(1.0);
    MaterialParams linear = m;
    linear.law = BondLawKind::Linear;
    const BondLaw shape = BondLaw::fromMaterial(m, 1.0);
    const auto infinity = std::numeric_limits<double>::infinity();
    const MassSpring tpLinear(lattice, SpringModel::TwoParameter, linear, kH, infinity);
    for (SpringModel model : {SpringModel::TwoParameter, SpringModel::VanGelder}) {
        MaterialParams mm = m;
        if (model == SpringModel::VanGelder) mm.poissonRatio = 1.0 / 3.0;
        MassSpring springs(lattice, model, mm, kH, infinity);
        double worst = 0.0;
        for (double e = 0.01; e <= 0.2 + 1e-9; e += 0.01) {
            const Pull p = uniaxial(springs, lattice, e);
            recordUniaxial(springs, lattice, e, p.lateral);
            worst = std::max(worst, std::abs(p.tension - shape.force(e)) / m.yieldStrain);
            if (model == SpringModel::TwoParameter && e < m.yieldStrain - 1e-9) {
                EXPECT_EQ(p.tension, uniaxial(tpLinear, lattice, e).tension) << "elastic";
            }
            std::printf("%s e = %.2f: tension / (E h H) = %.5f, f(e)/c = %.5f\n", nameOf(model), e,
                        p.tension, shape.force(e));
        }
        std::printf("%s elastoplastic: worst |T - f/c| / eta0 = %.4f\n", nameOf(model), worst);
        EXPECT_LT(worst, model == SpringModel::TwoParameter ? 0.06 : 1e-9) << nameOf(model);
    }
}

TEST(SpringLaws, ElastoplasticTrianglesKeepAPermanentSetAfterUnloading) {
    // Equibiaxial stretch to 15%: every side and height strain of every triangle is 15%, so
    // the triangle is exactly the 1D bond: unloaded, it is force-free at the permanent strain
    // eta_max - f(eta_max)/c of eq. 20 and pushes back at its rest shape.
    const Lattice lattice = patch(0.2);
    const MaterialParams m = elastoplastic(1.0);
    const BondLaw shape = BondLaw::fromMaterial(m, 1.0);
    const double top = 0.15, set = shape.plasticStrain({top});
    ASSERT_GT(set, 0.1);
    for (SpringModel model : {SpringModel::TwoParameter, SpringModel::VanGelder}) {
        MassSpring springs(lattice, model, m, kH, std::numeric_limits<double>::infinity());
        std::vector<Eigen::Vector3d> v(lattice.positions.size(), Eigen::Vector3d::Zero());
        const std::size_t n = lattice.positions.size();
        std::vector<Eigen::Vector3d> loaded(n), atSet(n), atRest(n);
        loaded = springs.advanceAt(scaled(lattice, 1 + top), v, 1e-3);
        atSet = springs.forcesAt(scaled(lattice, 1 + set));
        atRest = springs.forcesAt(lattice.positions);
        std::printf("%s: permanent set %.5f; force there / at rest = %.2e\n", nameOf(model), set,
                    maxNorm(atSet) / maxNorm(atRest));
        EXPECT_GT(maxNorm(atRest), 0.5 * maxNorm(loaded)) << nameOf(model) << ": pushes back";
        EXPECT_LT(maxNorm(atSet), 1e-9 * maxNorm(atRest)) << nameOf(model);
    }

    // Uniaxially: pulled to 15% along x and let go, the sheet rests where its tension is zero:
    // where the rows along the pull are back at their plastic rest length, the 1D permanent
    // strain (measured: to 1e-10).
    MassSpring springs(lattice, SpringModel::TwoParameter, m, kH,
                       std::numeric_limits<double>::infinity());
    for (double e = 0.01; e <= top + 1e-9; e += 0.01)
        recordUniaxial(springs, lattice, e, uniaxial(springs, lattice, e).lateral);
    double lo = 0.0, hi = top;
    for (int it = 0; it < 40; ++it) {
        const double mid = 0.5 * (lo + hi);
        (uniaxial(springs, lattice, mid).tension > 0.0 ? hi : lo) = mid;
    }
    const double rest = 0.5 * (lo + hi);
    std::printf("mass_spring_tp uniaxial permanent set %.5f (1D %.5f)\n", rest, set);
    EXPECT_NEAR(rest, set, 1e-6 * set);
    EXPECT_LT(uniaxial(springs, lattice, 0.0).tension, -0.5 * set)
        << "pushed back to its rest length it is in compression";
}

TEST(SpringLaws, PowerLawStiffeningIsReportedInCompressionWithLookAhead) {
    // Equibiaxial compression: every spring, side and height strain is the same, so
    // stiffening() is exactly phi'(eta) of eq. 19, and with the particles closing in at
    // velocity v it is phi' at the strain dt ahead.
    const Lattice lattice = patch(0.2);
    const MaterialParams m = powerLaw();
    const BondLaw shape = BondLaw::fromMaterial(m, 1.0);
    for (SpringModel model : {SpringModel::TwoParameter, SpringModel::VanGelder}) {
        MassSpring springs(lattice, model, m, kH, std::numeric_limits<double>::infinity());
        const int n = int(lattice.positions.size());
        std::vector<Eigen::Vector3d> still(n, Eigen::Vector3d::Zero()), f(n);
        f = springs.advanceAt(scaled(lattice, 1.1), still, 1e-3);
        EXPECT_EQ(springs.stiffening(), 1.0) << nameOf(model) << ": stretched, no stiffening";
        f = springs.advanceAt(scaled(lattice, 0.8), still, 1e-3);
        EXPECT_NEAR(springs.stiffening(), shape.powerLawStiffening(-0.2), 1e-9) << nameOf(model);
        EXPECT_GT(springs.stiffening(), 2.0) << nameOf(model);
        std::vector<Eigen::Vector3d> closing(n);  // strain rate -50/s: -0.25 after dt = 1e-3
        for (int i = 0; i < n; ++i) closing[i] = -50.0 * lattice.positions[i];
        f = springs.advanceAt(scaled(lattice, 0.8), closing, 1e-3);
        EXPECT_NEAR(springs.stiffening(), shape.powerLawStiffening(-0.25), 1e-6) << nameOf(model);
        std::printf("%s: stiffening %.4f at -20%%, %.4f looking ahead to -25%%\n", nameOf(model),
                    shape.powerLawStiffening(-0.2), springs.stiffening());
    }
    // A squeezed power-law sheet makes the Membrane cut its steps.
    MembraneParams p;
    p.solver = "mass_spring_tp";
    p.sheet.size = {0.2, 0.2};
    p.material = m;
    p.material.density = 5000;
    Membrane squeezed(p);
    for (int i = 0; i < squeezed.particleCount(); ++i)
        squeezed.positions()[i] = 0.7 * squeezed.restPositions()[i];
    squeezed.step();
    EXPECT_GT(squeezed.extraSubsteps(), 0);
}

TEST(SpringLaws, RigidMotionGivesZeroForceWithEveryLaw) {
    const Lattice lattice = patch(0.2);
    const int n = int(lattice.positions.size());
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    const Eigen::Vector3d shift(0.3, -1.0, 2.0);
    for (const MaterialParams& m : {powerLaw(), elastoplastic(1.0)})
        for (SpringModel model : {SpringModel::TwoParameter, SpringModel::VanGelder}) {
            MassSpring springs(lattice, model, m, kH, std::numeric_limits<double>::infinity());
            std::vector<Eigen::Vector3d> x = scaled(lattice, 1.1), v(n, Eigen::Vector3d::Zero());
            for (int i = 0; i < n; ++i)  // a deformed, yielded state
                for (int a = 0; a < 3; ++a)
                    x[i][a] += 2e-3 * (2.0 * uniformFromHash(5, std::uint64_t(3 * i + a)) - 1.0);
            std::vector<Eigen::Vector3d> before(n), after(n);
            before = springs.advanceAt(x, v, 1e-3);
            for (auto& p : x) p = R * p + shift;
            after = springs.forcesAt(x);
            double worst = 0.0;
            Eigen::Vector3d total = Eigen::Vector3d::Zero();
            for (int i = 0; i < n; ++i) {
                worst = std::max(worst, (after[i] - R * before[i]).norm());
                total += before[i];
            }
            EXPECT_LT(worst, 1e-10 * maxNorm(before)) << nameOf(model);
            EXPECT_LT(total.norm(), 1e-12 * maxNorm(before) * n) << nameOf(model);

            MassSpring fresh(lattice, model, m, kH, std::numeric_limits<double>::infinity());
            std::vector<Eigen::Vector3d> moved = lattice.positions;
            for (auto& p : moved) p = R * p + shift;
            after = fresh.advanceAt(moved, v, 1e-3);
            EXPECT_LT(maxNorm(after), 1e-9 * maxNorm(before)) << nameOf(model) << " at rest";
        }
}

TEST(SpringLaws, YieldedSpringsFeedTheDamageField) {
    // Every bond of the Membrane lies along a spring (horizon 1.5 dx): stretched equibiaxially
    // past the yield strain, each spring's strength left (eq. 27's gamma) is the damage.
    for (std::string solver : {"mass_spring_tp", "mass_spring_vg"}) {
        MembraneParams p;
        p.solver = solver;
        p.sheet.size = {0.2, 0.2};
        p.material = elastoplastic(1.0);
        p.material.density = 5000;
        Membrane m(p);
        for (int i = 0; i < m.particleCount(); ++i) m.positions()[i] = 1.1 * m.restPositions()[i];
        m.step();
        m.updateDamage();
        const double gamma = BondLaw::fromMaterial(p.material, 1.0).strengthLeft({0.1});
        double lowest = 1.0, highest = 0.0;
        for (double d : m.damage()) lowest = std::min(lowest, d), highest = std::max(highest, d);
        std::printf("damage %.4f..%.4f, 1 - gamma(0.1) = %.4f\n", lowest, highest, 1 - gamma);
        EXPECT_GT(1.0 - gamma, 0.4);
        EXPECT_NEAR(lowest, 1.0 - gamma, 1e-9);
        EXPECT_NEAR(highest, 1.0 - gamma, 1e-9);
    }
}

TEST(SpringLaws, OneAndTwoThreadsGiveIdenticalBitsWithEveryLaw) {
    for (const MaterialParams& law : {powerLaw(), elastoplastic(0.05)})
        for (std::string solver : {"mass_spring_tp", "mass_spring_vg"}) {
            MembraneParams p;
            p.solver = solver;
            p.sheet.size = {1.0, 1.0};
            p.sheet.perturbationAmplitude = 1e-4;
            p.material = law;
            p.material.density = 5000;
            p.material.fractureEnergy = 0.05;  // breaks at 1.2%
            p.material.yieldStrain = 0.005;
            p.notches = {Notch{{{-0.25, 0.0085}, {0.0, 0.0085}}}};
            p.boundaries = support::pullingGrips();
            const std::size_t broken = support::expectSameBitsWithOneAndTwoThreads(p, 200);
            std::printf("%s law %d: %zu broken bonds with 1 and 2 threads\n", solver.c_str(),
                        int(law.law), broken);
        }
}
