// VALIDATION.md, "uniaxial / biaxial patch test, strain 1e-4: E_eff = E, nu_eff = 1/3 in the
// interior, within 1% (interior), edge softening reported and corrected to <= 3%".
//
// A uniform affine strain is imposed on a hexagonal sheet and the virial stress of single
// particles (Membrane::particleStress) is read back. Plane stress with nu = 1/3:
//   uniaxial strain e along n:  sigma_nn = E e / (1 - nu^2),  sigma_tt = nu E e / (1 - nu^2),
//   so nu_eff = sigma_tt / sigma_nn and E_eff = sigma_nn (1 - nu_eff^2) / e;
//   biaxial strain e:           sigma_xx = sigma_yy = E e / (1 - nu),
//   so E_eff = sigma (1 - nu_eff) / e with the nu_eff of the uniaxial case.
// The edge softening and its correction are measured on whole strips (strip_test.cpp): a single
// edge particle's virial stress has no continuum meaning to compare with.

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "sim/Membrane.h"
#include "tests/sim/Peridynamic.h"

using namespace rend::sim;

namespace {

constexpr double kE = 2e4;
constexpr double kStrain = 1e-4;

MembraneParams hexSheet() {
    MembraneParams p;
    p.sheet.size = {0.6, 0.6};
    p.sheet.dx = 0.02;
    p.sheet.lattice = LatticeKind::Hexagonal;
    p.material.youngsModulus = kE;
    p.material.density = 5000;
    return p;
}

// In-plane stress (xx, yy, xy) of particle i under the small strain (exx, eyy, exy).
Eigen::Vector3d stressUnder(Membrane& m, int i, double exx, double eyy, double exy) {
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    F(0, 0) += exx;
    F(1, 1) += eyy;
    F(0, 1) += exy;
    F(1, 0) += exy;
    for (int k = 0; k < m.particleCount(); ++k) m.positions()[k] = F * m.restPositions()[k];
    const Eigen::Matrix3d s = rend::test::particleStress(m, i);
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

}  // namespace

TEST(ValidationPatch, InteriorHasModulusEAndPoissonOneThirdUnderUniaxialAndBiaxialStrain) {
    // Target: E_eff / E and nu_eff within 1% of 1 and 1/3 (VALIDATION.md, patch test).
    Membrane m(hexSheet());
    const int centre = m.nearestParticle({0, 0});
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
