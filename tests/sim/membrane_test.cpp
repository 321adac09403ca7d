// Tests of the membrane core against closed-form answers (VALIDATION.md).

#include "sim/Membrane.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstring>
#include <numbers>
#include <utility>

#include "tests/sim/Peridynamic.h"

using namespace rend::sim;

namespace {

MembraneParams smallSheet(LatticeKind lattice, double size = 0.6, double dx = 0.02) {
    MembraneParams p;
    p.sheet.size = {size, size};
    p.sheet.dx = dx;
    p.sheet.lattice = lattice;
    p.sheet.thickness = 1e-3;
    p.material.youngsModulus = 2e4;
    p.material.density = 5000;
    return p;
}

void applyAffine(Membrane& m, const Eigen::Matrix3d& F) {
    for (int i = 0; i < m.particleCount(); ++i) m.positions()[i] = F * m.restPositions()[i];
}

// In-plane stiffness (Voigt: xx, yy, xy) of particle i measured from three small affine strains.
Eigen::Matrix3d voigtStiffness(Membrane& m, int i, double e) {
    Eigen::Matrix3d C;
    const Eigen::Vector3d strains[3] = {{e, 0, 0}, {0, e, 0}, {0, 0, e}};  // exx, eyy, 2exy
    for (int k = 0; k < 3; ++k) {
        Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
        F(0, 0) += strains[k][0];
        F(1, 1) += strains[k][1];
        F(0, 1) += 0.5 * strains[k][2];
        F(1, 0) += 0.5 * strains[k][2];
        applyAffine(m, F);
        const Eigen::Matrix3d s = rend::test::particleStress(m, i);
        C.col(k) = Eigen::Vector3d(s(0, 0), s(1, 1), s(0, 1)) / e;
    }
    return C;
}

struct Elastic {
    double youngs;
    double poisson;
};

// E and nu for uniaxial stress along angle phi, from the compliance S = C^-1.
Elastic directionalModulus(const Eigen::Matrix3d& C, double phi) {
    const Eigen::Matrix3d S = C.inverse();
    const double c = std::cos(phi), s = std::sin(phi);
    const Eigen::Vector3d stress(c * c, s * s, c * s);
    const Eigen::Vector3d strain = S * stress;  // exx, eyy, 2exy
    const double along = stress.dot(strain);
    const Eigen::Vector3d across(s * s, c * c, -c * s);
    return {1.0 / along, -across.dot(strain) / along};
}

}  // namespace

TEST(Lattice, InteriorNeighbourCountForHorizonOneAndAHalfSpacings) {
    // R = 1.5 dx reaches the 6 nearest neighbours of a hexagonal lattice (the next shell is at
    // sqrt(3) dx) and the 4 + 4 edge and diagonal neighbours of a square one (diagonal sqrt(2) dx).
    for (auto [kind, expected] : {std::pair{LatticeKind::Hexagonal, 6}, {LatticeKind::Square, 8}}) {
        Membrane m(smallSheet(kind));
        const int centre = m.nearestParticle({0, 0});
        EXPECT_EQ(m.bonds().familySize(centre), expected);
    }
}

TEST(Lattice, HexagonalSheetHasTheExpectedParticleCountAndTriangles) {
    // The paper's 2 x 2 sheet at dx = 0.02: 101 columns, 116 rows with every other row one short.
    MembraneParams p = smallSheet(LatticeKind::Hexagonal, 2.0, 0.02);
    Membrane m(p);
    EXPECT_EQ(m.particleCount(), 58 * 101 + 58 * 100);
    // Every triangle edge is a bond at R = 1.5 dx, and triangles tile the sheet's area.
    FrameView v = m.view(0);
    double area = 0.0;
    for (const auto& t : v.restTriangles) {
        for (int e = 0; e < 3; ++e) ASSERT_GE(v.findBond(t[e], t[(e + 1) % 3]), 0);
        const Eigen::Vector3d a = v.restPositions[t[1]] - v.restPositions[t[0]];
        const Eigen::Vector3d b = v.restPositions[t[2]] - v.restPositions[t[0]];
        EXPECT_GT(a.cross(b).z(), 0.0) << "triangles are counter-clockwise from +z";
        area += 0.5 * a.cross(b).z();
    }
    // 115 strips between rows, each a trapezoid of widths 2.0 and 1.98.
    EXPECT_NEAR(area, 115 * 1.99 * 0.02 * std::sqrt(3.0) / 2.0, 1e-9);
}

TEST(Bonds, EveryBondIsStoredFromBothEndsWithTheSameRestLengthAndWeight) {
    Membrane m(smallSheet(LatticeKind::Square));
    const BondFamilies& b = m.bonds();
    FrameView v = m.view(0);
    for (int i = 0; i < b.particleCount(); ++i)
        for (int k = b.offsets[i]; k < b.offsets[i + 1]; ++k) {
            const int back = v.findBond(b.partners[k], i);
            ASSERT_GE(back, 0);
            EXPECT_EQ(b.restLength[back], b.restLength[k]);
            EXPECT_EQ(b.weight[k], 1.0 - b.restLength[k] / m.horizon());
        }
}

TEST(Bonds, RigidTranslationAndRotationGiveZeroForce) {
    Membrane m(smallSheet(LatticeKind::Hexagonal));
    const Eigen::Matrix3d R =
        (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
    const Eigen::Vector3d t(3.0, -1.5, 0.25);
    for (int i = 0; i < m.particleCount(); ++i) m.positions()[i] = R * m.restPositions()[i] + t;
    std::vector<Eigen::Vector3d> f;
    m.computeForces(f);
    // Relative to the force of one bond at unit strain.
    const double unit =
        rend::test::micromodulus(m) * m.volumes()[0] * m.volumes()[0] / (1.5 * 0.02);
    double worst = 0.0;
    for (const auto& fi : f) worst = std::max(worst, fi.norm());
    EXPECT_LE(worst / unit, 1e-12);
}

namespace {

/// Moves every particle of m off its rest place by up to a few millimetres; returns the forces.
std::vector<Eigen::Vector3d> deformed(Membrane& m) {
    for (int i = 0; i < m.particleCount(); ++i)
        m.positions()[i] += Eigen::Vector3d(0.003 * std::sin(17.0 * i), 0.002 * std::cos(5.0 * i),
                                            0.004 * std::sin(3.0 * i));
    std::vector<Eigen::Vector3d> f;
    m.computeForces(f);
    return f;
}

/// The central difference of m's strain energy at particle i, axis by axis, against -f[i].
void expectForceIsMinusEnergyGradient(Membrane& m, const std::vector<Eigen::Vector3d>& f, int i,
                                      double relative, double absolute) {
    const double h = 1e-7;
    for (int axis = 0; axis < 3; ++axis) {
        m.positions()[i][axis] += h;
        const double up = m.strainEnergy();
        m.positions()[i][axis] -= 2 * h;
        const double down = m.strainEnergy();
        m.positions()[i][axis] += h;
        EXPECT_NEAR(-(up - down) / (2 * h), f[i][axis], relative * f[i].norm() + absolute)
            << "particle " << i << ", axis " << axis;
    }
}

}  // namespace

TEST(Bonds, ForceIsTheNegativeGradientOfStrainEnergy) {
    Membrane m(smallSheet(LatticeKind::Hexagonal, 0.2));
    const std::vector<Eigen::Vector3d> f = deformed(m);
    expectForceIsMinusEnergyGradient(m, f, m.nearestParticle({0, 0}), 1e-6, 1e-12);
}

// Past 8,192 particles the strain energy is summed in blocks on every thread
// (PeridynamicBonds::strainEnergyOf): still the force's potential at a particle of each block,
// and the same bits on one thread and two.
TEST(Bonds, TheStrainEnergyInBlocksIsTheForcesPotentialOnAnyThreadCount) {
    Membrane m(smallSheet(LatticeKind::Hexagonal, 2.0));
    ASSERT_GT(m.particleCount(), 8192 + 1000) << "two blocks";
    const std::vector<Eigen::Vector3d> f = deformed(m);
    for (const int i : {5, 8191, 8192, 9000, m.particleCount() - 2})
        expectForceIsMinusEnergyGradient(m, f, i, 1e-5, 1e-10);
    omp_set_num_threads(1);
    const double one = m.strainEnergy();
    omp_set_num_threads(2);
    const double two = m.strainEnergy();
    EXPECT_EQ(std::memcmp(&one, &two, sizeof one), 0) << one << " against " << two;
    EXPECT_GT(one, 0.0);
}

TEST(Membrane, MomentumIsConservedWithoutBoundaryConditions) {
    Membrane m(smallSheet(LatticeKind::Hexagonal, 0.4));
    for (int i = 0; i < m.particleCount(); ++i)
        m.velocities()[i] =
            0.05 * Eigen::Vector3d(std::sin(1.3 * i), std::cos(2.1 * i), std::sin(0.7 * i + 1.0));
    const Eigen::Vector3d before = m.totalMomentum();
    double scale = 0.0;
    for (int i = 0; i < m.particleCount(); ++i) scale += m.masses()[i] * m.velocities()[i].norm();
    for (int s = 0; s < 500; ++s) m.step();
    EXPECT_LE((m.totalMomentum() - before).norm() / scale, 1e-12);
    EXPECT_GT(m.strainEnergy(), 0.0) << "the sheet did deform";
}

// Patch test (VALIDATION.md): a uniform strain of 1e-4 must give E_eff = E and nu = 1/3 in the
// interior, pulled along x and along a diagonal.
TEST(PatchTest, HexagonalLatticeIsIsotropicWithInputModulusInTheInterior) {
    Membrane m(smallSheet(LatticeKind::Hexagonal));
    const double E = 2e4;
    const Eigen::Matrix3d C = voigtStiffness(m, m.nearestParticle({0, 0}), 1e-4);
    for (double phi : {0.0, std::numbers::pi / 4, std::numbers::pi / 6}) {
        const Elastic e = directionalModulus(C, phi);
        std::printf("hexagonal  phi=%5.1f deg  E_eff/E = %.5f  nu = %.4f\n",
                    phi * 180 / std::numbers::pi, e.youngs / E, e.poisson);
        EXPECT_NEAR(e.youngs / E, 1.0, 0.01);
        EXPECT_NEAR(e.poisson, 1.0 / 3.0, 0.01);
    }
}

TEST(PatchTest, SquareLatticeIsAnisotropicSoHexagonalIsTheDefault) {
    Membrane m(smallSheet(LatticeKind::Square));
    const double E = 2e4;
    const Eigen::Matrix3d C = voigtStiffness(m, m.nearestParticle({0, 0}), 1e-4);
    const Elastic alongX = directionalModulus(C, 0.0);
    const Elastic diagonal = directionalModulus(C, std::numbers::pi / 4);
    std::printf("square     E_eff/E along x = %.4f (nu %.3f), along diagonal = %.4f (nu %.3f)\n",
                alongX.youngs / E, alongX.poisson, diagonal.youngs / E, diagonal.poisson);
    EXPECT_GT(std::abs(alongX.youngs / diagonal.youngs - 1.0), 0.01);
    EXPECT_EQ(SheetParams{}.lattice, LatticeKind::Hexagonal);
}

TEST(PatchTest, EdgeSofteningIsReportedAndThePaperConstantIsNotCalibrated) {
    MembraneParams p = smallSheet(LatticeKind::Hexagonal);
    Membrane m(p);
    const double E = 2e4;
    // A particle on the left edge misses half its family: the skin effect of VALIDATION.md.
    const int edge = m.nearestParticle({-0.3, 0.0});
    const Elastic atEdge = directionalModulus(voigtStiffness(m, edge, 1e-4), std::numbers::pi / 2);
    std::printf("hexagonal edge particle: E_eff/E along the edge = %.4f\n", atEdge.youngs / E);
    EXPECT_LT(atEdge.youngs / E, 0.95) << "edges are softer than the interior";

    p.material.micromodulus = MicromodulusMode::Paper;
    Membrane paper(p);
    const Elastic literal =
        directionalModulus(voigtStiffness(paper, paper.nearestParticle({0, 0}), 1e-4), 0.0);
    std::printf("paper's literal c = 18K/(pi R^4): E_eff/E = %.4g at dx = 0.02, h = 1e-3\n",
                literal.youngs / E);
    EXPECT_GT(std::abs(literal.youngs / E - 1.0), 0.01);
}

TEST(Membrane, OneAndTwoThreadsGiveIdenticalBits) {
    MembraneParams p = smallSheet(LatticeKind::Hexagonal, 1.0);
    p.sheet.perturbationAmplitude = 1e-4;
    BoundaryCondition left, right;
    left.kind = right.kind = BoundaryKind::Velocity;
    left.region.max.x() = -0.49;
    right.region.min.x() = 0.49;
    left.velocity = {-0.1, 0, 0.02};
    right.velocity = {0.1, 0, 0};
    left.rampTime = right.rampTime = 0.01;
    p.boundaries = {left, right};
    p.time.dt = 1e-4;
    auto run = [&](int threads) {
        omp_set_num_threads(threads);
        Membrane m(p);
        EXPECT_GT(m.particleCount(), kParallelThreshold) << "must take the parallel path";
        for (int s = 0; s < 400; ++s) m.step();
        return m.positions();
    };
    const auto one = run(1);
    const auto two = run(2);
    ASSERT_EQ(one.size(), two.size());
    EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size() * sizeof(one[0])), 0);
    EXPECT_GT((one[0] - Membrane(p).restPositions()[0]).norm(), 1e-3) << "the sheet moved";
}

TEST(TimeStep, StableBoundMatchesTheClosedFormForTheHexagonalLattice) {
    // Interior hexagonal particle: 6 bonds of stiffness k = c W V^2 / dx^2 with W = 1/3 and
    // c = 6E / (6 W V), so sum k = 6E V / dx^2 and dt = sqrt(2 rho V / sum k) = dx sqrt(rho/(3E)).
    MembraneParams p = smallSheet(LatticeKind::Hexagonal);
    Membrane m(p);
    EXPECT_NEAR(m.stableTimeStep(), 0.02 * std::sqrt(5000.0 / (3.0 * 2e4)), 1e-12);
    EXPECT_DOUBLE_EQ(m.timeStep(), 0.8 * m.stableTimeStep()) << "dt = auto uses safety 0.8";
}

TEST(TimeStep, RunsAtTheBoundStayBoundedAndRunsAboveItAreCaught) {
    MembraneParams p = smallSheet(LatticeKind::Hexagonal, 0.4);
    p.sheet.perturbationAmplitude = 1e-3;
    Membrane stable(p);
    stable.setTimeStep(stable.stableTimeStep());
    const double e0 = stable.strainEnergy();
    for (int s = 0; s < 3000; ++s) stable.step();
    EXPECT_LE(stable.kineticEnergy() + stable.strainEnergy(), 1.5 * e0);

    Membrane unstable(p);
    unstable.setTimeStep(2.5 * unstable.stableTimeStep());
    EXPECT_THROW(
        {
            for (int s = 0; s < 3000; ++s) unstable.step();
        },
        NumericalBlowUp);
}

TEST(Guard, NonFiniteStateStopsWithinOneStepNamingTheParticle) {
    Membrane m(smallSheet(LatticeKind::Hexagonal, 0.3));
    for (int s = 0; s < 5; ++s) m.step();
    m.velocities()[42].x() = std::nan("");
    try {
        m.step();
        FAIL() << "no blow-up reported";
    } catch (const NumericalBlowUp& e) {
        EXPECT_EQ(e.particle, 42);
        EXPECT_EQ(e.step, 6);
        EXPECT_NE(std::string(e.what()).find("particle 42"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("use dt <="), std::string::npos) << e.what();
    }
}

TEST(Guard, WellBelowTheStableStepItBlamesTheForcesNotTheStep) {
    Membrane m(smallSheet(LatticeKind::Hexagonal, 0.3));
    m.setTimeStep(0.1 * m.stableTimeStep());
    for (int s = 0; s < 5; ++s) m.step();
    m.velocities()[42].x() = std::nan("");
    try {
        m.step();
        FAIL() << "no blow-up reported";
    } catch (const NumericalBlowUp& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("times below the stable limit"), std::string::npos) << message;
        EXPECT_EQ(message.find("use dt <="), std::string::npos) << message;
    }
}

namespace {

// A 0.4 m sheet pulled at 0.2 m/s (ramped over 0.01 s) on its right edge, pinned on its left.
MembraneParams pulledAndPinned() {
    MembraneParams p = smallSheet(LatticeKind::Hexagonal, 0.4);
    BoundaryCondition pull, pin;
    pull.kind = BoundaryKind::Velocity;
    pull.region.min.x() = 0.19;
    pull.velocity = {0.2, 0, 0};
    pull.rampTime = 0.01;
    pin.kind = BoundaryKind::Pinned;
    pin.region.max.x() = -0.19;
    p.boundaries = {pull, pin};
    p.time.dt = 1e-4;
    return p;
}

}  // namespace

TEST(Boundaries, VelocityRegionsFollowTheirRampAndPinnedRegionsStayPut) {
    const MembraneParams p = pulledAndPinned();
    Membrane m(p);
    const std::vector<int> counts = m.boundaryParticleCounts();
    EXPECT_GT(counts[0], 0);
    EXPECT_GT(counts[1], 0);
    const int pulled = m.nearestParticle({0.2, 0});
    const int pinned = m.nearestParticle({-0.2, 0});
    for (int s = 0; s < 50; ++s) m.step();  // halfway up the ramp
    EXPECT_NEAR(m.velocities()[pulled].x(), 0.2 * 0.5, 1e-12);
    for (int s = 0; s < 150; ++s) m.step();
    EXPECT_NEAR(m.velocities()[pulled].x(), 0.2, 1e-12);
    EXPECT_EQ(m.positions()[pinned], m.restPositions()[pinned]);
}

// The bound on every speed a step leaves for the next force pass (StepState::speedBound): the
// largest free particle's |v| or the boundaries' full speed, whichever is larger; unknown
// before the first step and again once the velocities may have changed (the writable
// accessor, a checkpoint read back).
TEST(Membrane, TheSpeedBoundCoversEveryParticleUntilTheVelocitiesChange) {
    const MembraneParams p = pulledAndPinned();
    for (const double kick : {0.0, 0.5}) {  // the boundary's speed is the largest, then a free one
        Membrane m(p);
        EXPECT_LT(m.stepState().speedBound, 0.0);
        m.velocities()[m.nearestParticle({0.0, 0.0})] = {0.0, 0.0, kick};
        for (int s = 0; s < 20; ++s) {
            m.step();
            double most = 0.0;
            for (const Eigen::Vector3d& v : std::as_const(m).velocities())
                most = std::max(most, v.norm());
            const double bound = m.stepState().speedBound;
            ASSERT_GE(bound, most) << "kick " << kick << ", step " << s;
            EXPECT_NEAR(bound, std::max(most, 0.2), 1e-12 * bound) << "kick " << kick;
        }
        const std::vector<std::byte> saved = m.saveState();
        m.step();
        m.loadState(saved);
        EXPECT_LT(m.stepState().speedBound, 0.0);
        m.step();
        EXPECT_GE(m.stepState().speedBound, 0.0);
        m.velocities();
        EXPECT_LT(m.stepState().speedBound, 0.0);
    }
}

TEST(Lattice, DiscOutlineHoldsItsAreaWorthOfParticlesAllInside) {
    MembraneParams p = smallSheet(LatticeKind::Hexagonal);
    p.sheet.outline = Outline::Disc;
    p.sheet.radius = 0.5;
    p.sheet.center = {0.3, -0.2, 0.1};
    Membrane m(p);
    const double cellArea = 0.02 * 0.02 * std::sqrt(3.0) / 2.0;
    EXPECT_NEAR(m.particleCount() * cellArea / (std::numbers::pi * 0.25), 1.0, 0.02);
    for (const auto& x : m.restPositions()) {
        EXPECT_LE((x.head<2>() - p.sheet.center.head<2>()).norm(), 0.5 + 1e-9);
        EXPECT_EQ(x.z(), 0.1);
    }
}

TEST(Membrane, FreeFallAcceleratesEveryParticleByGravityExactly) {
    // A sheet at rest in its rest shape has no bond force, so every particle falls alike:
    // symplectic Euler gives v = n dt g and z = -n (n+1) / 2 dt^2 g exactly up to rounding.
    MembraneParams p = smallSheet(LatticeKind::Hexagonal, 0.2);
    p.gravity = {0, 0, -9.81};
    p.time.dt = 1e-3;
    Membrane m(p);
    const int n = 100;
    for (int s = 0; s < n; ++s) m.step();
    for (int i = 0; i < m.particleCount(); ++i) {
        EXPECT_NEAR(m.velocities()[i].z(), -9.81 * n * 1e-3, 1e-12);
        EXPECT_NEAR(m.positions()[i].z(), -9.81 * 1e-6 * n * (n + 1) / 2.0, 1e-12);
    }
    EXPECT_NEAR(m.strainEnergy(), 0.0, 1e-20);
}
