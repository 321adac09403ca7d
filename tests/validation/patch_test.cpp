// VALIDATION.md, "uniaxial / biaxial patch test, strain 1e-4: E_eff = E, nu_eff = 1/3 in the
// interior, within 1% (interior), edge softening reported and corrected to <= 3%".
//
// A uniform affine strain is imposed on a hexagonal sheet and the virial stress of single
// particles (Membrane::particleStress) is read back. Plane stress with nu = 1/3:
//   uniaxial strain e along n:  sigma_nn = E e / (1 - nu^2),  sigma_tt = nu E e / (1 - nu^2),
//   so nu_eff = sigma_tt / sigma_nn and E_eff = sigma_nn (1 - nu_eff^2) / e;
//   biaxial strain e:           sigma_xx = sigma_yy = E e / (1 - nu),
//   so E_eff = sigma (1 - nu_eff) / e with the nu_eff of the uniaxial case.
// At a free edge the natural state is uniaxial stress along the edge, so there E_eff is read
// from the full in-plane compliance (three strains, Voigt) as 1 / S_tt along the edge (the metric
// of the README's 0.90, which is the 5-bond particle of the left edge). The dilatation ratio
// printed beside it is what the energy-method correction (S_interior / S_i per particle, the mean
// of both ends per bond) is built on.

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "sim/Membrane.h"

using namespace rend::sim;

namespace {

constexpr double kE = 2e4;
constexpr double kStrain = 1e-4;

MembraneParams hexSheet(bool surfaceCorrection) {
    MembraneParams p;
    p.sheet.size = {0.6, 0.6};
    p.sheet.dx = 0.02;
    p.sheet.lattice = LatticeKind::Hexagonal;
    p.material.youngsModulus = kE;
    p.material.density = 5000;
    p.material.surfaceCorrection = surfaceCorrection;
    return p;
}

int nearestParticle(const Membrane& m, const Eigen::Vector2d& at) {
    int best = 0;
    for (int i = 1; i < m.particleCount(); ++i)
        if ((m.restPositions()[i].head<2>() - at).norm() <
            (m.restPositions()[best].head<2>() - at).norm())
            best = i;
    return best;
}

// In-plane stress (xx, yy, xy) of particle i under the small strain (exx, eyy, exy).
Eigen::Vector3d stressUnder(Membrane& m, int i, double exx, double eyy, double exy) {
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    F(0, 0) += exx;
    F(1, 1) += eyy;
    F(0, 1) += exy;
    F(1, 0) += exy;
    for (int k = 0; k < m.particleCount(); ++k) m.positions()[k] = F * m.restPositions()[k];
    const Eigen::Matrix3d s = m.particleStress(i);
    return {s(0, 0), s(1, 1), s(0, 1)};
}

// Uniaxial strain kStrain along the unit direction (c, s): E_eff and nu_eff.
std::pair<double, double> uniaxialStrain(Membrane& m, int i, double phi) {
    const double c = std::cos(phi), s = std::sin(phi);
    const Eigen::Vector3d sig =
        stressUnder(m, i, kStrain * c * c, kStrain * s * s, kStrain * c * s);
    const double along = c * c * sig[0] + s * s * sig[1] + 2 * c * s * sig[2];
    const double across = s * s * sig[0] + c * c * sig[1] - 2 * c * s * sig[2];
    const double nu = across / along;
    return {along * (1 - nu * nu) / kStrain, nu};
}

// Uniaxial stress along phi from the compliance: E_eff = 1 / S_phi.
double uniaxialStressModulus(Membrane& m, int i, double phi) {
    Eigen::Matrix3d C;  // columns: exx, eyy, gamma_xy = 2 exy
    C.col(0) = stressUnder(m, i, kStrain, 0, 0) / kStrain;
    C.col(1) = stressUnder(m, i, 0, kStrain, 0) / kStrain;
    C.col(2) = stressUnder(m, i, 0, 0, 0.5 * kStrain) / kStrain;
    const double c = std::cos(phi), s = std::sin(phi);
    const Eigen::Vector3d stress(c * c, s * s, c * s);
    return 1.0 / stress.dot(C.inverse() * stress);
}

}  // namespace

TEST(ValidationPatch, InteriorHasModulusEAndPoissonOneThirdUnderUniaxialAndBiaxialStrain) {
    // Target: E_eff / E and nu_eff within 1% of 1 and 1/3 (VALIDATION.md, patch test).
    Membrane m(hexSheet(false));
    const int centre = nearestParticle(m, {0, 0});
    for (double deg : {0.0, 30.0, 45.0, 90.0}) {
        const auto [E, nu] = uniaxialStrain(m, centre, deg * std::numbers::pi / 180);
        std::printf(
            "interior, uniaxial strain 1e-4 along %4.0f deg: E_eff/E = %.6f  nu_eff = %.6f"
            "  (reference 1, 1/3; target 1%%)\n",
            deg, E / kE, nu);
        EXPECT_NEAR(E / kE, 1.0, 0.01) << deg;
        EXPECT_NEAR(nu, 1.0 / 3.0, 0.01 / 3.0) << deg;
    }
    const double nu = uniaxialStrain(m, centre, 0.0).second;
    const Eigen::Vector3d sig = stressUnder(m, centre, kStrain, kStrain, 0);
    const double Exx = sig[0] * (1 - nu) / kStrain, Eyy = sig[1] * (1 - nu) / kStrain;
    std::printf(
        "interior, biaxial strain 1e-4: sigma/(E e/(1-nu)) = %.6f, %.6f; E_eff/E = %.6f,"
        " %.6f  (target 1%%)\n",
        sig[0] / (kE * kStrain / (1 - 1.0 / 3)), sig[1] / (kE * kStrain / (1 - 1.0 / 3)), Exx / kE,
        Eyy / kE);
    EXPECT_NEAR(Exx / kE, 1.0, 0.01);
    EXPECT_NEAR(Eyy / kE, 1.0, 0.01);
    EXPECT_NEAR(sig[2] / (kE * kStrain), 0.0, 1e-9);
}

TEST(ValidationPatch, EdgeSofteningIsReportedAndTheSurfaceCorrectionStiffensSoftEdges) {
    // VALIDATION.md's target is corrected edges within 3% of E. The present correction (mean of
    // the ends' dilatational factors S_int/S_i) does not reach it: it is not direction-aware, so
    // it over-stiffens the straight bottom row and under-corrects the zig-zag tip (figures
    // printed below, README "Validation"). Until a directional correction lands (issue 5), this
    // test pins what holds: the correction moves every softened edge particle's dilatational
    // response towards the interior's, and leaves the interior alone.
    // Edge particles of the 0.6 m sheet: the left edge is a zig-zag (the row through y = 0 starts
    // at x = -0.29, its neighbours at x = -0.30), the bottom edge is a straight lattice row.
    struct Edge {
        const char* name;
        Eigen::Vector2d at;
        double alongDeg;
    };
    Membrane probe(hexSheet(false));
    double yBottom = 1e9;
    for (const auto& x : probe.restPositions()) yBottom = std::min(yBottom, x.y());
    const double row = 0.02 * std::sqrt(3.0) / 2;
    const Edge edges[] = {
        {"left edge, zig-zag tip (x=-0.30)", {-0.30, row}, 90.0},
        {"left edge, zig-zag notch (x=-0.29)", {-0.29, 0.0}, 90.0},
        {"bottom edge (straight row)", {0.0, yBottom}, 0.0},
        {"second row above the bottom edge", {0.01, yBottom + row}, 0.0},
    };
    for (const Edge& e : edges) {
        double modulus[2], bulk[2];
        int bonds = 0;
        for (int corrected = 0; corrected < 2; ++corrected) {
            Membrane m(hexSheet(corrected == 1));
            const int i = nearestParticle(m, e.at);
            ASSERT_LT((m.restPositions()[i].head<2>() - e.at).norm(), 1e-9) << e.name;
            bonds = m.bonds().offsets[i + 1] - m.bonds().offsets[i];
            modulus[corrected] =
                uniaxialStressModulus(m, i, e.alongDeg * std::numbers::pi / 180) / kE;
            // What the energy-method correction is built on: the particle's response to a
            // uniform dilatation, (sigma_xx + sigma_yy) / 2 against E e / (1 - nu).
            const Eigen::Vector3d sig = stressUnder(m, i, kStrain, kStrain, 0);
            bulk[corrected] = 0.5 * (sig[0] + sig[1]) / (kE * kStrain / (1 - 1.0 / 3));
        }
        std::printf(
            "%-34s (%d bonds) E_eff/E along the edge: uncorrected %.4f, surface-corrected %.4f"
            " (VALIDATION target 1 +- 3%%, not met yet); dilatation ratio %.4f -> %.4f\n",
            e.name, bonds, modulus[0], modulus[1], bulk[0], bulk[1]);
        if (bulk[0] < 0.97) {
            EXPECT_LT(std::abs(bulk[1] - 1.0), std::abs(bulk[0] - 1.0)) << e.name;
            EXPECT_GT(modulus[1], modulus[0]) << e.name << ": softer edges get stiffer";
        }
    }
}
