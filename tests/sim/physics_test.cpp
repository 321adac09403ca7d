// Bond laws, fracture and diffusion of the membrane paper (Sections 4-5) against closed forms.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "sim/Diffusion.h"
#include "sim/Fracture.h"
#include "sim/Membrane.h"
#include "sim/Random.h"
#include "tests/sim/Peridynamic.h"

using namespace rend::sim;

namespace {

MembraneParams sheet(double size = 0.4, double dx = 0.02) {
    MembraneParams p;
    p.sheet.size = {size, size};
    p.sheet.dx = dx;
    p.material.youngsModulus = 2e4;
    p.material.density = 5000;
    return p;
}

void stretchAffinely(Membrane& m, double eta) {
    for (int i = 0; i < m.particleCount(); ++i)
        m.positions()[i] = (1.0 + eta) * m.restPositions()[i];
}

double totalTheta(const Membrane& m) {
    double sum = 0.0;
    for (double t : m.theta()) sum += t;
    return sum;
}

BondLaw lawOf(BondLawKind kind) {
    MaterialParams m;
    m.law = kind;
    m.powerLawRatio = -0.1;
    m.powerLawExponent = 4.0;
    m.yieldStrain = 0.01;
    m.softening = 0.5;
    return BondLaw::fromMaterial(m, 3.0e7);
}

}  // namespace

TEST(BondLaw, EachLawsForceIsTheDerivativeOfItsEnergy) {
    for (BondLawKind kind :
         {BondLawKind::Linear, BondLawKind::PowerLaw, BondLawKind::Elastoplastic}) {
        const BondLaw law = lawOf(kind);
        // A yielded elastoplastic state: below its largest strain the energy is elastic about
        // the permanent strain.
        PlasticState state;
        if (kind == BondLawKind::Elastoplastic) state = law.yieldStep(0.02, state);
        for (double eta : {-0.3, -0.05, 0.0, 0.004, 0.015, 0.2, 0.9}) {
            if (kind == BondLawKind::Elastoplastic && eta + 1e-6 >= state.maxStrain)
                continue;  // on the loading path the bond yields, it is not elastic
            const double h = 1e-6;
            const double numeric =
                (law.energy(eta + h, state) - law.energy(eta - h, state)) / (2 * h);
            EXPECT_NEAR(numeric, law.force(eta, state), 1e-6 * law.c)
                << "law " << int(kind) << " eta " << eta;
        }
    }
}

TEST(BondLaw, EveryLawIsForceFreeAtRestWithStiffnessC) {
    for (BondLawKind kind :
         {BondLawKind::Linear, BondLawKind::PowerLaw, BondLawKind::Elastoplastic}) {
        const BondLaw law = lawOf(kind);
        EXPECT_NEAR(law.force(0.0), 0.0, 1e-9 * law.c);
        EXPECT_NEAR(law.energy(0.0), 0.0, 1e-9 * law.c);
        EXPECT_NEAR((law.force(1e-7) - law.force(-1e-7)) / 2e-7, law.c, 1e-5 * law.c);
    }
}

TEST(BondLaw, PowerLawRubberSoftensInTensionAndStiffensInCompression) {
    const BondLaw law = lawOf(BondLawKind::PowerLaw);
    EXPECT_LT(law.force(1.0), law.c * 1.0) << "eq. 19 with c* < 0 softens under large stretch";
    EXPECT_LT(law.force(-0.5), law.c * -0.5) << "1/s^3 resists collapse";
}

// Eq. 19 holds for s = 1 + eta > 0. Expansion can take a squashed bond's mechanical strain below
// -1 (alpha theta larger than its length); there the law must still push, never pull.
TEST(BondLaw, PowerLawPushesHowEverFarABondIsSquashed) {
    const BondLaw law = lawOf(BondLawKind::PowerLaw);
    const double held = law.force(BondLaw::kMostCompression);
    EXPECT_LT(held, law.force(-0.5));
    for (double eta : {-0.96, -1.0, -1.4, -3.0}) {
        EXPECT_EQ(law.force(eta), held) << eta;
        const double h = 1e-6;
        EXPECT_NEAR((law.energy(eta + h) - law.energy(eta - h)) / (2 * h), held, 1e-6 * -held)
            << "the energy goes on linearly, eta " << eta;
    }
    EXPECT_NEAR(law.energy(BondLaw::kMostCompression - 1e-9), law.energy(BondLaw::kMostCompression),
                1e-6 * -held);
}

TEST(BondLaw, ElastoplasticLoadingFollowsEquationTwentyAndKeepsAPermanentSet) {
    const BondLaw law = lawOf(BondLawKind::Elastoplastic);  // eta0 = 0.01, beta = 0.5
    PlasticState state;
    for (double eta : {0.005, 0.02, 0.05}) {
        state = law.yieldStep(eta, state);
        // Eq. 20 on the monotonic path: c eta up to eta0, then c eta0 exp(-beta (eta-eta0)/eta0).
        const double expected =
            eta < 0.01 ? law.c * eta : law.c * 0.01 * std::exp(-0.5 * (eta - 0.01) / 0.01);
        EXPECT_NEAR(law.force(eta, state), expected, 1e-9 * law.c) << eta;
    }
    const double permanent = law.plasticStrain(state);
    EXPECT_NEAR(permanent, 0.05 - law.force(0.05, state) / law.c, 1e-15);
    EXPECT_NEAR(law.force(permanent, state), 0.0, 1e-9 * law.c) << "unloaded, it keeps a stretch";
    EXPECT_LT(law.force(0.03, state), law.force(0.05, state)) << "unloading is elastic";
    // Eq. 27: gamma = exp(-beta (eta - eta0)/eta0) at the largest strain.
    EXPECT_NEAR(law.strengthLeft(state), std::exp(-0.5 * 4.0), 1e-12);
}

TEST(Fracture, CriticalStretchMatchesTheClosedFormOfTheHexagonalLattice) {
    // Interior hexagonal particle at R = 1.5 dx: S = 6 (1/3) dx V and c = 3E/V, so
    // eta_c = sqrt(2 pi G / (c S)) = sqrt(pi G / (3 E dx)).
    MembraneParams p = sheet();
    p.material.fractureEnergy = 11.3;
    Membrane m(p);
    EXPECT_NEAR(rend::test::criticalStretch(m),
                std::sqrt(std::numbers::pi * 11.3 / (3 * 2e4 * 0.02)), 1e-12);
    p.material.criticalStretch = CriticalStretchMode::Paper;
    EXPECT_DOUBLE_EQ(rend::test::criticalStretch(Membrane(p)),
                     std::sqrt(4 * std::numbers::pi * 11.3 / (9 * 2e4 * 0.03)));
    EXPECT_EQ(rend::test::criticalStretch(Membrane(sheet())),
              std::numeric_limits<double>::infinity());
}

TEST(Fracture, BondsBreakJustAboveTheCriticalStretchAndNotBelow) {
    MembraneParams p = sheet(0.2);
    p.material.fractureEnergy = 11.3;
    for (double factor : {0.999, 1.001}) {
        Membrane m(p);
        stretchAffinely(m, factor * rend::test::criticalStretch(m));
        m.step();
        EXPECT_EQ(m.brokenBondCount() > 0, factor > 1.0) << factor;
        if (factor > 1.0) {
            EXPECT_EQ(m.brokenBondCount(), m.bondCount());
        }
    }
}

TEST(Fracture, DegradationLowersTheCriticalStretchWithTheta) {
    MembraneParams p = sheet(0.2);
    p.material.fractureEnergy = 11.3;
    p.material.strengthLoss = 0.5;  // theta = 1 halves eta_c
    p.diffusion.initial = 1.0;
    Membrane m(p);
    stretchAffinely(m, 0.51 * rend::test::criticalStretch(m));
    m.step();
    EXPECT_EQ(m.brokenBondCount(), m.bondCount());
}

TEST(Fracture, DamageNeverHeals) {
    MembraneParams p = sheet(0.4);
    p.material.fractureEnergy = 0.5;
    p.notches = {Notch{{{-0.21, 0.0}, {-0.1, 0.0}}}};
    BoundaryCondition top, bottom;
    top.kind = bottom.kind = BoundaryKind::Velocity;
    top.region.min.y() = 0.19;
    bottom.region.max.y() = -0.19;
    top.velocity = {0, 0.3, 0};
    bottom.velocity = {0, -0.3, 0};
    p.boundaries = {top, bottom};
    p.time.dt = 2e-4;
    Membrane m(p);
    std::vector<std::uint8_t> before = m.damageState().bondAlive();
    std::size_t maxBroken = 0;
    for (int s = 0; s < 3000; ++s) {
        if (s == 1500) {  // push the edges back together: nothing may reconnect
            std::swap(m.velocities(), m.velocities());
            p.boundaries[0].velocity *= -1.0;
        }
        m.step();
        for (std::size_t b = 0; b < before.size(); ++b)
            ASSERT_LE(m.damageState().bondAlive()[b], before[b]);
        before = m.damageState().bondAlive();
        maxBroken = std::max(maxBroken, m.brokenBondCount());
    }
    EXPECT_GT(m.brokenBondCount(), m.notchedBondCount()) << "the crack grew";
    EXPECT_EQ(m.brokenBondCount(), maxBroken);
    m.updateDamage();
    EXPECT_GT(*std::max_element(m.damage().begin(), m.damage().end()), 0.3);
}

TEST(Fracture, ANotchBreaksExactlyTheBondsItCrosses) {
    MembraneParams p = sheet(0.4);
    Membrane probe(p);
    // A horizontal notch halfway between two lattice rows, crossing x in [-0.1, 0.1].
    double rowBelow = -1e9, rowAbove = 1e9;
    for (const auto& x : probe.restPositions()) {
        if (x.y() <= 0.0) rowBelow = std::max(rowBelow, x.y());
        if (x.y() > 0.0) rowAbove = std::min(rowAbove, x.y());
    }
    const double y = 0.5 * (rowBelow + rowAbove);
    p.notches = {Notch{{{-0.1, y}, {0.1, y}}}};
    Membrane m(p);
    const BondFamilies& bonds = m.bonds();
    const std::vector<std::uint8_t>& bondAlive = m.damageState().bondAlive();
    std::size_t expected = 0;
    for (int i = 0; i < m.particleCount(); ++i)
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
            const Eigen::Vector3d a = m.restPositions()[i];
            const Eigen::Vector3d c = m.restPositions()[bonds.partners[b]];
            // Independent of the code under test: interpolate where the bond meets the line.
            const bool straddles = (a.y() - y) * (c.y() - y) < 0.0;
            const double x = a.x() + (c.x() - a.x()) * (y - a.y()) / (c.y() - a.y());
            const bool crosses = straddles && x >= -0.1 && x <= 0.1;
            EXPECT_EQ(bondAlive[b] == 0, crosses) << i << " -> " << bonds.partners[b];
            expected += crosses;
        }
    EXPECT_EQ(m.notchedBondCount(), expected / 2);
    EXPECT_GE(expected / 2, 18u) << "about two bonds per dx of notch";
}

TEST(Fracture, ANotchAlongAParticleRowCutsTheRowOffOnceAndLeavesNoLooseParticle) {
    // A notch drawn exactly through a row of particles (y = 0 on an odd number of rows): the
    // bonds between that row and the row below break, the row stays bonded to the row above.
    MembraneParams p = sheet(0.4);
    p.sheet.size = {0.4, 0.02 * std::sqrt(3.0) / 2 * 20};  // 21 rows, the middle one at y = 0
    Membrane probe(p);
    int onLine = 0;
    for (const auto& x : probe.restPositions()) onLine += std::abs(x.y()) < 1e-12;
    ASSERT_GT(onLine, 10) << "the set-up needs a row at y = 0";
    p.notches = {Notch{{{-0.105, 0.0}, {0.105, 0.0}}}};
    Membrane m(p);
    const BondFamilies& bonds = m.bonds();
    const std::vector<std::uint8_t>& bondAlive = m.damageState().bondAlive();
    std::size_t expected = 0;
    for (int i = 0; i < m.particleCount(); ++i) {
        const Eigen::Vector3d a = m.restPositions()[i];
        int alive = 0;
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
            const Eigen::Vector3d c = m.restPositions()[bonds.partners[b]];
            const Eigen::Vector3d lo = a.y() < c.y() ? a : c, hi = a.y() < c.y() ? c : a;
            // Independent of the code under test: the bond joins the row to the one below, and
            // its upper end lies on the notch.
            const bool crosses =
                std::abs(hi.y()) < 1e-12 && lo.y() < -1e-12 && std::abs(hi.x()) <= 0.105;
            EXPECT_EQ(bondAlive[b] == 0, crosses) << i << " -> " << bonds.partners[b];
            expected += crosses;
            alive += bondAlive[b];
        }
        EXPECT_GE(alive, 2) << "particle " << i << " was cut loose";
    }
    EXPECT_EQ(m.notchedBondCount(), expected / 2);
    EXPECT_EQ(expected / 2, 2u * 11) << "two bonds down from each of the 11 particles on it";
}

TEST(Diffusion, InsulatedSheetWithoutSourcesConservesTheTotal) {
    MembraneParams p = sheet(0.4);
    p.material.conductivity = 50.0;
    p.diffusion.initial = 0.0;
    p.diffusion.spots = {};
    Membrane m(p);
    ASSERT_FALSE(m.hasDiffusion()) << "nothing to diffuse yet: no theta is kept";
    p.diffusion.initial = 1e-30;  // just to switch diffusion on
    Membrane d(p);
    ASSERT_TRUE(d.hasDiffusion());
    for (int i = 0; i < d.particleCount(); ++i) d.theta()[i] = 1.0 + std::sin(0.37 * i);
    const double before = totalTheta(d);
    for (int s = 0; s < 2000; ++s) d.step();
    EXPECT_NEAR(totalTheta(d) / before, 1.0, 1e-12);
    const auto [lo, hi] = std::minmax_element(d.theta().begin(), d.theta().end());
    EXPECT_LT(*hi - *lo, 0.5) << "and it did diffuse";
}

TEST(Diffusion, NothingCrossesABrokenBond) {
    MembraneParams p = sheet(0.4);
    p.material.conductivity = 50.0;
    p.diffusion.initial = 1e-30;
    p.notches = {Notch{{{-0.3, 0.003}, {0.3, 0.003}}}};  // cuts the sheet in two
    Membrane m(p);
    for (int i = 0; i < m.particleCount(); ++i)
        m.theta()[i] = m.restPositions()[i].y() > 0.003 ? 1.0 : 0.0;
    for (int s = 0; s < 2000; ++s) m.step();
    for (int i = 0; i < m.particleCount(); ++i)
        EXPECT_EQ(m.theta()[i], m.restPositions()[i].y() > 0.003 ? 1.0 : 0.0);
}

TEST(Diffusion, SubstepsWhenItsBoundIsTighterThanTheMechanics) {
    MembraneParams p = sheet(0.2);
    p.material.conductivity = 1e4;  // very fast diffusion
    p.diffusion.initial = 1e-30;
    p.time.dt = 1e-3;
    Membrane m(p);
    ASSERT_LT(m.diffusion()->stableTimeStep(), 1e-3);
    for (int i = 0; i < m.particleCount(); ++i) m.theta()[i] = (i % 2) ? 1.0 : 0.0;
    for (int s = 0; s < 50; ++s) m.step();
    for (double t : m.theta()) ASSERT_TRUE(t >= -1e-9 && t <= 1.0 + 1e-9) << "stayed bounded";
}

TEST(Diffusion, SpotsAddTheirRateOnlyWhileActive) {
    MembraneParams p = sheet(0.4);
    p.diffusion.spots = {DiffusionSpot{{0.0, 0.0}, 0.05, 2.0, 0.01, 0.02}};
    p.time.dt = 1e-3;
    Membrane m(p);
    for (int s = 0; s < 100; ++s) m.step();  // t = 0.1, the spot ran from 0.01 to 0.03
    EXPECT_NEAR(m.maxTheta(), 2.0 * 0.02, 1e-9);
}

// The spots' particles, found through the order by x, are those of the loop over every point:
// on a lattice (many points sharing an x, discs whose rims pass through points) and on random
// points, for small discs, discs wider than the sheet and discs beside it.
TEST(Diffusion, ASpotsParticlesAreThoseOfTheLoopOverEveryPoint) {
    std::vector<Eigen::Vector3d> points;
    for (int k = 0; k < 41 * 41; ++k) points.emplace_back(0.01 * (k % 41), 0.01 * (k / 41), 0.0);
    for (int k = 0; k < 2000; ++k)
        points.emplace_back(0.4 * uniformFromHash(3, 2 * k), 0.4 * uniformFromHash(3, 2 * k + 1),
                            0.0);
    const std::vector<int> byX = orderByX(points);
    for (std::size_t k = 1; k < byX.size(); ++k)
        ASSERT_TRUE(points[byX[k - 1]].x() < points[byX[k]].x() ||
                    (points[byX[k - 1]].x() == points[byX[k]].x() && byX[k - 1] < byX[k]));
    int discs = 0, narrow = 0;
    for (int d = 0; d < 400; ++d) {
        Eigen::Vector2d center(0.6 * uniformFromHash(4, 3 * d) - 0.1,
                               0.6 * uniformFromHash(4, 3 * d + 1) - 0.1);
        double radius = 0.2 * std::pow(uniformFromHash(4, 3 * d + 2), 3.0);
        if (d % 4 == 0) {  // on a lattice point, its rim through others
            center = points[(d * 37) % (41 * 41)].head<2>();
            radius = 0.01 * (1 + d % 5);
        }
        if (d == 1) radius = 10.0;
        std::vector<int> expected;
        for (int i = 0; i < int(points.size()); ++i)
            if ((points[i].head<2>() - center).norm() <= radius) expected.push_back(i);
        const std::vector<int> found = pointsInDisc(points, byX, center, radius);
        ASSERT_EQ(found, expected)
            << "disc " << d << " at " << center.transpose() << " radius " << radius;
        discs += !expected.empty();
        narrow += 4 * expected.size() < points.size() && !expected.empty();
    }
    EXPECT_GT(narrow, 200);  // the run by x, not the loop over every point
    EXPECT_GT(discs - narrow, 0);
    // Without the order (or with another sheet's), every point is tested.
    EXPECT_EQ(pointsInDisc(points, {}, Eigen::Vector2d(0.2, 0.2), 0.05),
              pointsInDisc(points, byX, Eigen::Vector2d(0.2, 0.2), 0.05));
}

TEST(Coupling, FreeExpansionGivesStrainAlphaDeltaTheta) {
    MembraneParams p = sheet(0.4);
    p.material.expansion = 1e-3;
    p.diffusion.initial = 2.0;  // a uniform rise of 2: free strain 2e-3
    Membrane m(p);
    stretchAffinely(m, 2e-3);
    std::vector<Eigen::Vector3d> f;
    m.computeForces(f);
    double worst = 0.0;
    for (const auto& fi : f) worst = std::max(worst, fi.norm());
    const double unit = rend::test::micromodulus(m) * m.volumes()[0] * m.volumes()[0] / 0.03;
    EXPECT_LE(worst / unit, 1e-12) << "the expanded sheet is in equilibrium";

    // Released from its rest shape with damping, the sheet settles at the same strain.
    p.damping = 20.0;
    p.time.dt = 1e-3;
    Membrane released(p);
    for (int s = 0; s < 20000; ++s) released.step();
    double strain = 0.0;
    int count = 0;
    const auto& b = released.bonds();
    for (int i = 0; i < released.particleCount(); ++i)
        for (int k = b.offsets[i]; k < b.offsets[i + 1]; ++k, ++count)
            strain += (released.positions()[b.partners[k]] - released.positions()[i]).norm() /
                          b.restLength[k] -
                      1.0;
    EXPECT_NEAR(strain / count, 2e-3, 1e-6);
}

TEST(Coupling, MomentumIsConservedWithNonUniformTheta) {
    MembraneParams p = sheet(0.4);
    p.material.expansion = 0.05;
    p.material.conductivity = 1.0;
    p.material.law = BondLawKind::PowerLaw;
    p.material.powerLawRatio = -0.05;
    p.diffusion.initial = 1e-30;
    Membrane m(p);
    for (int i = 0; i < m.particleCount(); ++i) m.theta()[i] = std::sin(0.11 * i);
    for (int s = 0; s < 500; ++s) m.step();
    double scale = 0.0;
    for (int i = 0; i < m.particleCount(); ++i) scale += m.masses()[i] * m.velocities()[i].norm();
    ASSERT_GT(scale, 0.0);
    EXPECT_LE(m.totalMomentum().norm() / scale, 1e-12);
}
