// The MPM solver (sim/Mpm.h) and its grid (sim/MpmGrid.h): APIC's exactness and conservation,
// and seed 002's boundary particles and enrichment.

#include "sim/Mpm.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "sim/Membrane.h"
#include "sim/MpmGrid.h"

using namespace rend::sim;

namespace {

/// A jittered sheet of particles in the plane z = 0.003 (off the grid's planes).
std::vector<Eigen::Vector3d> jitteredSheet(int side, double dx, std::mt19937& rng) {
    std::uniform_real_distribution<double> jitter(-0.3 * dx, 0.3 * dx);
    std::vector<Eigen::Vector3d> x;
    for (int i = 0; i < side; ++i)
        for (int j = 0; j < side; ++j)
            x.emplace_back(i * dx + jitter(rng), j * dx + jitter(rng), 0.003 + 0.1 * jitter(rng));
    return x;
}

/// Angular momentum about the origin, with APIC's affine spin m (tr D - D) w, D = h^2 / 4 I:
/// the vector part of C - C^T, times m h^2 / 4.
Eigen::Vector3d angularMomentum(const std::vector<Eigen::Vector3d>& x,
                                const std::vector<Eigen::Vector3d>& v,
                                const std::vector<Eigen::Matrix3d>& C, const std::vector<double>& m,
                                double h) {
    Eigen::Vector3d L = Eigen::Vector3d::Zero();
    for (std::size_t p = 0; p < x.size(); ++p) {
        const Eigen::Matrix3d& c = C[p];
        L += m[p] * x[p].cross(v[p]);
        L += m[p] * h * h / 4 *
             Eigen::Vector3d(c(2, 1) - c(1, 2), c(0, 2) - c(2, 0), c(1, 0) - c(0, 1));
    }
    return L;
}

}  // namespace

TEST(MpmGrid, AnAffineVelocityFieldSurvivesTheRoundTripExactly) {
    std::mt19937 rng(3);
    const std::vector<Eigen::Vector3d> x = jitteredSheet(12, 0.02, rng);
    const Eigen::Matrix3d L = Eigen::Matrix3d::Random();
    const Eigen::Vector3d b = Eigen::Vector3d::Random();
    std::vector<Eigen::Vector3d> v(x.size());
    std::vector<Eigen::Matrix3d> C(x.size(), L);
    for (std::size_t p = 0; p < x.size(); ++p) v[p] = b + L * x[p];
    const std::vector<double> mass(x.size(), 0.3);
    const std::vector<std::uint8_t> onGrid(x.size(), 1);
    MpmGrid grid(0.01);
    grid.transfer(x, mass, onGrid, v, C);
    double worstV = 0.0, worstC = 0.0;
    for (std::size_t p = 0; p < x.size(); ++p) {
        worstV = std::max(worstV, (v[p] - (b + L * x[p])).norm());
        worstC = std::max(worstC, (C[p] - L).norm());
    }
    EXPECT_LT(worstV, 1e-13);
    EXPECT_LT(worstC, 1e-12) << "C_p is the field's gradient";
}

TEST(MpmGrid, TheTransferKeepsMassMomentumAndAngularMomentum) {
    std::mt19937 rng(5);
    const std::vector<Eigen::Vector3d> x = jitteredSheet(10, 0.02, rng);
    std::normal_distribution<double> normal;
    std::vector<Eigen::Vector3d> v(x.size());
    std::vector<Eigen::Matrix3d> C(x.size(), Eigen::Matrix3d::Zero());
    std::vector<double> mass(x.size());
    for (std::size_t p = 0; p < x.size(); ++p) {
        v[p] = Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
        mass[p] = 0.1 + 0.05 * std::abs(normal(rng));
    }
    const std::vector<std::uint8_t> onGrid(x.size(), 1);
    const double h = 0.01;
    MpmGrid grid(h);
    double totalMass = 0.0;
    Eigen::Vector3d momentum = Eigen::Vector3d::Zero();
    for (std::size_t p = 0; p < x.size(); ++p) totalMass += mass[p], momentum += mass[p] * v[p];
    const Eigen::Vector3d L0 = angularMomentum(x, v, C, mass, h);
    for (int round = 0; round < 3; ++round) grid.transfer(x, mass, onGrid, v, C);
    EXPECT_NEAR(grid.gridMass(), totalMass, 1e-13 * totalMass);
    EXPECT_LT((grid.gridMomentum() - momentum).norm(), 1e-13 * momentum.norm());
    Eigen::Vector3d after = Eigen::Vector3d::Zero();
    for (std::size_t p = 0; p < x.size(); ++p) after += mass[p] * v[p];
    EXPECT_LT((after - momentum).norm(), 1e-13 * momentum.norm());
    EXPECT_LT((angularMomentum(x, v, C, mass, h) - L0).norm(), 1e-12 * L0.norm())
        << "APIC keeps the angular momentum, its affine spin included";
}

// The reason for APIC: a rigid spin through a grid without the affine part (PIC) loses its
// angular momentum to the grid's smoothing, transfer after transfer.
TEST(MpmGrid, WithoutTheAffinePartASpinLosesItsAngularMomentum) {
    std::mt19937 rng(7);
    std::vector<Eigen::Vector3d> x = jitteredSheet(16, 0.02, rng);
    const Eigen::Vector3d centre(0.15, 0.15, 0.0);
    const std::vector<double> mass(x.size(), 1.0);
    const std::vector<std::uint8_t> onGrid(x.size(), 1);
    auto spinOf = [&](bool apic) {
        std::vector<Eigen::Vector3d> v(x.size());
        std::vector<Eigen::Matrix3d> C(x.size(), Eigen::Matrix3d::Zero());
        for (std::size_t p = 0; p < x.size(); ++p)
            v[p] = Eigen::Vector3d::UnitZ().cross(x[p] - centre);
        MpmGrid grid(0.01);
        for (int k = 0; k < 200; ++k) {
            if (!apic) std::fill(C.begin(), C.end(), Eigen::Matrix3d::Zero());
            grid.transfer(x, mass, onGrid, v, C);
        }
        double L = 0.0;
        for (std::size_t p = 0; p < x.size(); ++p) L += (x[p] - centre).cross(v[p]).z();
        return L;
    };
    double L0 = 0.0;
    for (const auto& p : x) L0 += (p - centre).head<2>().squaredNorm();
    const double apic = spinOf(true) / L0, pic = spinOf(false) / L0;
    std::printf("rigid spin after 200 transfers: APIC keeps %.6f, PIC %.6f of L\n", apic, pic);
    EXPECT_GT(apic, 0.99);  // the rest is in C_p's spin (the test above)
    EXPECT_LT(pic, 0.9);
}

TEST(Mpm, BoundaryParticlesAreTheEndsOfEdgesAcrossAMaterialJump) {
    MembraneParams p;
    p.solver = "mpm";
    p.sheet.size = {0.4, 0.2};
    p.sheet.dx = 0.02;
    p.material.youngsModulus = 2e4;
    p.material.density = 1000;
    MaterialMap soft;
    soft.property = MappedProperty::YoungsModulus;
    soft.min = {0.0, -1.0};
    soft.max = {1.0, 1.0};
    soft.factor = 0.25;
    p.materialMaps = {soft};
    Membrane m(p);
    const auto& mpm = dynamic_cast<const Mpm&>(m.solver());
    const auto& tri = m.lattice().triangles;
    std::vector<std::uint8_t> expected(m.particleCount(), 0);
    for (const auto& t : tri)
        for (int s = 0; s < 3; ++s) {
            const int i = t[s], j = t[(s + 1) % 3];
            if ((m.restPositions()[i].x() >= 0) != (m.restPositions()[j].x() >= 0))
                expected[i] = expected[j] = 1;
        }
    EXPECT_EQ(mpm.boundaryParticles(), expected);
    m.step();
    EXPECT_GT(mpm.enrichedCount(), 0);
    EXPECT_LT(mpm.enrichedCount(), m.particleCount() / 2);

    p.mpm.enrich = false;  // plain MPM: no boundary, every free particle on the grid
    Membrane plain(p);
    plain.step();
    EXPECT_EQ(dynamic_cast<const Mpm&>(plain.solver()).enrichedCount(), 0);
}

TEST(Mpm, ACracksEdgesAreBoundaryParticlesAndGripsStayOffTheGrid) {
    MembraneParams p;
    p.solver = "mpm";
    p.sheet.size = {0.4, 0.4};
    p.sheet.dx = 0.02;
    p.material.youngsModulus = 2e4;
    p.material.density = 1000;
    p.notches = {Notch{{{-0.1, 0.011}, {0.1, 0.011}}}};
    BoundaryCondition pin;
    pin.region.max.x() = -0.19;
    p.boundaries = {pin};
    Membrane m(p);
    m.step();
    const auto& mpm = dynamic_cast<const Mpm&>(m.solver());
    const auto& kept = m.damageState().keptTriangles();
    for (std::size_t t = 0; t < kept.size(); ++t)
        if (!kept[t])
            for (const int corner : m.lattice().triangles[t])
                EXPECT_TRUE(mpm.boundaryParticles()[corner]) << "corner " << corner;
    int pinned = 0;
    for (const auto& x : m.restPositions()) pinned += x.x() <= -0.19;
    EXPECT_GE(mpm.enrichedCount(), pinned);
    for (int i = 0; i < m.particleCount(); ++i)
        if (m.restPositions()[i].x() <= -0.19)
            EXPECT_EQ(m.velocities()[i], Eigen::Vector3d::Zero());
}
