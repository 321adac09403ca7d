// The continuum-mechanics report's worked examples (seeds/001_b1a2c3e9c54b18d5.txt, Sections
// 2.5 and 3.1) and the properties the FEM reference model must have whatever the report says.
//
// Two printed values disagree with their own derivation and are tested at the derived value:
//  - eq. 2.12 prints E_yy = 1; F^T F = diag(0.25, 1) for a rotated scaling, so E_yy = 0 (and
//    the stress of eq. 2.13 is only reproduced with E_yy = 0).
//  - eq. 3.9 prints f_123 = 1.5 m^2 sigma (-1/3, -2/3, -2/3) = (-3.125, -6.251, -6.249) 10^9 N;
//    a negative stress times a negative normal is positive, and only the positive sign makes
//    the four face forces sum to zero and gives the vertex forces printed in eq. 3.10.

#include "sim/Continuum.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

using namespace rend::sim::continuum;

namespace {

// Rubber, as in both examples.
constexpr double kYoung = 1.0e7;
constexpr double kPoisson = 0.4999;

// The target is 3 significant digits: relative 5e-4, widened to half a unit of the last
// printed digit where the report printed fewer than four.
void expectPrinted(double actual, double printed, double lastDigit, const char* where) {
    const double tolerance = std::max(5e-4 * std::abs(printed), 0.5 * lastDigit);
    EXPECT_NEAR(actual, printed, tolerance) << where;
}

// Printed zeros are exact in both examples (diagonal strains), so hold them tightly.
void expectZero(double actual, double scale, const char* where) {
    EXPECT_NEAR(actual, 0.0, 1e-12 * scale) << where;
}

Tet tetFromColumns(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    Tet t;
    t << a, b, c, d;
    return t;
}

// Eq. 3.4.
Tet exampleRestTet() { return tetFromColumns({1, 1, 0}, {3, 1, 0}, {1, 3, 0}, {1, 1, 1}); }
Tet exampleCurrentTet() { return tetFromColumns({1, 1, 0}, {3, 1, 0}, {1, 2, 0}, {1, 1, 1}); }

// An irregular element and a deformation with stretch, shear and rotation, so that no check
// passes by symmetry.
Tet irregularRestTet() {
    return tetFromColumns({0.1, -0.2, 0.05}, {1.3, 0.1, -0.1}, {0.2, 0.9, 0.3}, {-0.1, 0.3, 1.1});
}
Mat3 someDeformation() {
    Mat3 A;
    A << 1.15, 0.2, -0.05, -0.1, 0.85, 0.12, 0.07, -0.08, 1.3;
    return A;
}
Tet applyAffine(const Mat3& A, const Vec3& t, const Tet& tet) { return (A * tet).colwise() + t; }
Mat3 someRotation() {
    return Eigen::AngleAxisd(1.1, Vec3(1, -2, 0.5).normalized()).toRotationMatrix();
}

double maxAbs(const Tet& m) { return m.cwiseAbs().maxCoeff(); }

}  // namespace

TEST(ContinuumLame, LameParametersGiveBackYoungsModulusAndPoissonRatio) {
    const Lame l = lameParameters(kYoung, kPoisson);
    EXPECT_NEAR(l.mu * (3 * l.lambda + 2 * l.mu) / (l.lambda + l.mu), kYoung, 1e-9 * kYoung);
    EXPECT_NEAR(l.lambda / (2 * (l.lambda + l.mu)), kPoisson, 1e-12);
    EXPECT_THROW(lameParameters(kYoung, 0.5), std::invalid_argument);
    EXPECT_THROW(lameParameters(kYoung, -1.0), std::invalid_argument);
    EXPECT_THROW(lameParameters(0.0, 0.3), std::invalid_argument);
}

TEST(ContinuumHooke, TensorFormEqualsTheVoigtMatrixOfEq2_8WithEngineeringShear) {
    const double E = 2.0e5, nu = 0.3;
    Eigen::Matrix<double, 6, 6> C = Eigen::Matrix<double, 6, 6>::Zero();
    C.topLeftCorner<3, 3>().setConstant(nu);
    C.topLeftCorner<3, 3>().diagonal().setConstant(1 - nu);
    C.bottomRightCorner<3, 3>().diagonal().setConstant((1 - 2 * nu) / 2);
    C *= E / ((1 + nu) * (1 - 2 * nu));
    Mat3 strain;
    strain << 0.01, 0.004, -0.002, 0.004, -0.003, 0.006, -0.002, 0.006, 0.02;
    // Eq. 2.8's shear factor (1 - 2 nu)/2 is mu, so its shear entries are engineering strains.
    Eigen::Matrix<double, 6, 1> voigt;
    voigt << strain(0, 0), strain(1, 1), strain(2, 2), 2 * strain(1, 2), 2 * strain(0, 2),
        2 * strain(0, 1);
    const Eigen::Matrix<double, 6, 1> s = C * voigt;
    const Mat3 S = hookeStress(strain, lameParameters(E, nu));
    const double scale = E * 0.02;
    EXPECT_NEAR(S(0, 0), s(0), 1e-12 * scale);
    EXPECT_NEAR(S(1, 1), s(1), 1e-12 * scale);
    EXPECT_NEAR(S(2, 2), s(2), 1e-12 * scale);
    EXPECT_NEAR(S(1, 2), s(3), 1e-12 * scale);
    EXPECT_NEAR(S(0, 2), s(4), 1e-12 * scale);
    EXPECT_NEAR(S(0, 1), s(5), 1e-12 * scale);
    EXPECT_TRUE(S.isApprox(S.transpose(), 0.0));
}

// Section 2.5: the duck, squished by 2 along x and rotated by 30 degrees, in 2D. It is
// embedded in 3D as plane strain (F_zz = 1), which is what the 3x3 Voigt matrix of eq. 2.13
// (eq. 2.8 with the z rows dropped, E_zz = 0) computes.
TEST(ContinuumDuckExample, DeformationGradientOfTheSquishedAndRotatedDuckMatchesEq2_11) {
    const double a = std::numbers::pi / 6;
    Mat3 map = Mat3::Identity();
    map.topLeftCorner<2, 2>() << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
    map = map * Vec3(0.5, 1, 1).asDiagonal();  // eq. 2.10: rotation after scaling
    // Recover F from a tetrahedron carried by the map, as a simulation would see it.
    const Tet rest = irregularRestTet();
    const Mat3 F = deformationGradient(rest, applyAffine(map, Vec3(3, -1, 2), rest));
    expectPrinted(F(0, 0), 0.433, 1e-3, "eq. 2.11 F_xx");
    expectPrinted(F(0, 1), -0.500, 1e-3, "eq. 2.11 F_xy");
    expectPrinted(F(1, 0), 0.250, 1e-3, "eq. 2.11 F_yx");
    expectPrinted(F(1, 1), 0.866, 1e-3, "eq. 2.11 F_yy");
    EXPECT_NEAR(F(2, 2), 1.0, 1e-12);
    EXPECT_NEAR(F.row(2).head<2>().norm() + F.col(2).head<2>().norm(), 0.0, 1e-12);
}

TEST(ContinuumDuckExample, GreenStrainMatchesEq2_12WithTheDerivedZeroForEyy) {
    const double a = std::numbers::pi / 6;
    Mat3 F = Mat3::Identity();
    F.topLeftCorner<2, 2>() << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
    F = F * Vec3(0.5, 1, 1).asDiagonal();
    const Mat3 E = greenStrain(F);
    expectPrinted(E(0, 0), -0.375, 1e-3, "eq. 2.12 E_xx");
    expectZero(E(0, 1), 1.0, "eq. 2.12 E_xy");
    expectZero(E(1, 0), 1.0, "eq. 2.12 E_yx");
    // Eq. 2.12 prints 1 here; the rotation cancels in F^T F and the y axis is not scaled.
    expectZero(E(1, 1), 1.0, "eq. 2.12 E_yy (printed 1, derived 0)");
}

TEST(ContinuumDuckExample, RubberStressMatchesEqs2_13And2_14) {
    const double a = std::numbers::pi / 6;
    Mat3 F = Mat3::Identity();
    F.topLeftCorner<2, 2>() << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
    F = F * Vec3(0.5, 1, 1).asDiagonal();
    const Mat3 S = secondPiolaKirchhoff(F, lameParameters(kYoung, kPoisson));
    // The report calls this sigma; it is the stress of the Green strain, i.e. S, not the
    // Cauchy stress of the rotated duck.
    expectPrinted(S(0, 0), -6.251e9, 1e6, "eq. 2.13/2.14 sigma_xx");
    expectPrinted(S(1, 1), -6.249e9, 1e6, "eq. 2.13/2.14 sigma_yy");
    expectZero(S(0, 1), 6e9, "eq. 2.13/2.14 sigma_xy");
    expectZero(S(1, 0), 6e9, "eq. 2.14 sigma_yx");

    // Eq. 2.13 as printed: the 3x3 plane-strain Voigt matrix times (E_xx, E_yy, E_xy).
    const double nu = kPoisson;
    Mat3 C;
    C << 1 - nu, nu, 0, nu, 1 - nu, 0, 0, 0, (1 - 2 * nu) / 2;
    C *= kYoung / ((1 + nu) * (1 - 2 * nu));
    const Mat3 E = greenStrain(F);
    const Vec3 s = C * Vec3(E(0, 0), E(1, 1), 2 * E(0, 1));
    EXPECT_NEAR(s(0), S(0, 0), 1e-12 * 6e9);
    EXPECT_NEAR(s(1), S(1, 1), 1e-12 * 6e9);
    EXPECT_NEAR(s(2), S(0, 1), 1e-12 * 6e9);
}

// Section 3.1: one rubber tetrahedron whose vertex 2 moves from y = 3 to y = 2.
TEST(ContinuumTetExample, TranslatedVerticesAndEdgeMatricesMatchEqs3_5And3_6) {
    const Mat3 Dm = edgeMatrix(exampleRestTet());
    const Mat3 Ds = edgeMatrix(exampleCurrentTet());
    // Eq. 3.5 (vertex 0 at the origin) and eq. 3.6: Dm = diag(2, 2, 1), Ds = diag(2, 1, 1).
    EXPECT_TRUE(Dm.isApprox(Vec3(2, 2, 1).asDiagonal().toDenseMatrix(), 1e-15));
    EXPECT_TRUE(Ds.isApprox(Vec3(2, 1, 1).asDiagonal().toDenseMatrix(), 1e-15));
}

TEST(ContinuumTetExample, DeformationGradientMatchesEq3_6) {
    const Mat3 F = deformationGradient(exampleRestTet(), exampleCurrentTet());
    expectPrinted(F(0, 0), 1.0, 1.0, "eq. 3.6 F_xx");
    expectPrinted(F(1, 1), 0.5, 0.1, "eq. 3.6 F_yy");
    expectPrinted(F(2, 2), 1.0, 1.0, "eq. 3.6 F_zz");
    EXPECT_NEAR(F(0, 0), 1.0, 1e-15);
    EXPECT_NEAR(F(1, 1), 0.5, 1e-15);
    EXPECT_NEAR(F(2, 2), 1.0, 1e-15);
    EXPECT_NEAR((F - F.diagonal().asDiagonal().toDenseMatrix()).norm(), 0.0, 1e-15);
}

TEST(ContinuumTetExample, GreenStrainMatchesEq3_7) {
    const Mat3 E = greenStrain(deformationGradient(exampleRestTet(), exampleCurrentTet()));
    expectPrinted(E(1, 1), -0.375, 1e-3, "eq. 3.7 E_yy");
    expectZero(E(0, 0), 1.0, "eq. 3.7 E_xx");
    expectZero(E(2, 2), 1.0, "eq. 3.7 E_zz");
    expectZero((E - E.diagonal().asDiagonal().toDenseMatrix()).norm(), 1.0, "eq. 3.7 shear");
}

TEST(ContinuumTetExample, StressMatchesEq3_8) {
    const Mat3 S = secondPiolaKirchhoff(deformationGradient(exampleRestTet(), exampleCurrentTet()),
                                        lameParameters(kYoung, kPoisson));
    expectPrinted(S(0, 0), -6.249e9, 1e6, "eq. 3.8 sigma_xx");
    expectPrinted(S(1, 1), -6.251e9, 1e6, "eq. 3.8 sigma_yy");
    expectPrinted(S(2, 2), -6.249e9, 1e6, "eq. 3.8 sigma_zz");
    expectZero((S - S.diagonal().asDiagonal().toDenseMatrix()).norm(), 6e9, "eq. 3.8 shear");
}

TEST(ContinuumTetExample, FaceAreasAndInwardNormalsMatchEq3_9) {
    const auto faces = tetFaces(exampleCurrentTet());
    // Face k is opposite vertex k: f_123, f_023, f_013, f_012.
    EXPECT_NEAR(faces[3].area, 1.0, 1e-15);  // f_012
    EXPECT_NEAR(faces[2].area, 1.0, 1e-15);  // f_013
    EXPECT_NEAR(faces[1].area, 0.5, 1e-15);  // f_023
    EXPECT_NEAR(faces[0].area, 1.5, 1e-15);  // f_123
    EXPECT_TRUE(faces[3].inwardNormal.isApprox(Vec3(0, 0, 1), 1e-15));
    EXPECT_TRUE(faces[2].inwardNormal.isApprox(Vec3(0, 1, 0), 1e-15));
    EXPECT_TRUE(faces[1].inwardNormal.isApprox(Vec3(1, 0, 0), 1e-15));
    EXPECT_TRUE(faces[0].inwardNormal.isApprox(Vec3(-1, -2, -2) / 3.0, 1e-15));
}

TEST(ContinuumTetExample, FaceForcesMatchEq3_9WithTheDerivedSignOfF123) {
    const Tet current = exampleCurrentTet();
    const Mat3 S = secondPiolaKirchhoff(deformationGradient(exampleRestTet(), current),
                                        lameParameters(kYoung, kPoisson));
    const Tet f = faceForces(current, S);
    const double scale = 6e9;
    // f_012
    expectZero(f(0, 3), scale, "eq. 3.9 f_012 x");
    expectZero(f(1, 3), scale, "eq. 3.9 f_012 y");
    expectPrinted(f(2, 3), -6.249e9, 1e6, "eq. 3.9 f_012 z");
    // f_013
    expectZero(f(0, 2), scale, "eq. 3.9 f_013 x");
    expectPrinted(f(1, 2), -6.251e9, 1e6, "eq. 3.9 f_013 y");
    expectZero(f(2, 2), scale, "eq. 3.9 f_013 z");
    // f_023
    expectPrinted(f(0, 1), -3.125e9, 1e6, "eq. 3.9 f_023 x");
    expectZero(f(1, 1), scale, "eq. 3.9 f_023 y");
    expectZero(f(2, 1), scale, "eq. 3.9 f_023 z");
    // f_123: printed (-3.125, -6.251, -6.249) 10^9 N, derived with the opposite sign.
    expectPrinted(f(0, 0), 3.125e9, 1e6, "eq. 3.9 f_123 x (printed negative)");
    expectPrinted(f(1, 0), 6.251e9, 1e6, "eq. 3.9 f_123 y (printed negative)");
    expectPrinted(f(2, 0), 6.249e9, 1e6, "eq. 3.9 f_123 z (printed negative)");
    // A closed surface under uniform stress: the face forces cancel.
    EXPECT_NEAR(f.rowwise().sum().norm(), 0.0, 1e-12 * scale);
}

TEST(ContinuumTetExample, ReportVertexForcesMatchEq3_10) {
    const Tet f = reportTetNodalForces(exampleRestTet(), exampleCurrentTet(),
                                       lameParameters(kYoung, kPoisson));
    const double scale = 6e9;
    expectPrinted(f(0, 0), -1.04e9, 1e7, "eq. 3.10 f(x0) x");
    expectPrinted(f(1, 0), -2.08e9, 1e7, "eq. 3.10 f(x0) y");
    expectPrinted(f(2, 0), -2.08e9, 1e7, "eq. 3.10 f(x0) z");
    expectPrinted(f(0, 1), 1.04e9, 1e7, "eq. 3.10 f(x1) x");
    expectZero(f(1, 1), scale, "eq. 3.10 f(x1) y");
    expectZero(f(2, 1), scale, "eq. 3.10 f(x1) z");
    expectZero(f(0, 2), scale, "eq. 3.10 f(x2) x");
    expectPrinted(f(1, 2), 2.08e9, 1e7, "eq. 3.10 f(x2) y");
    expectZero(f(2, 2), scale, "eq. 3.10 f(x2) z");
    expectZero(f(0, 3), scale, "eq. 3.10 f(x3) x");
    expectZero(f(1, 3), scale, "eq. 3.10 f(x3) y");
    expectPrinted(f(2, 3), 2.08e9, 1e7, "eq. 3.10 f(x3) z");
    EXPECT_NEAR(f.rowwise().sum().norm(), 0.0, 1e-12 * scale);
}

TEST(ContinuumTetExample, EnergyConsistentForcesDifferFromEq3_10AtThisLargeStrain) {
    // Not printed in the report: -V P Dm^-T with V = 2/3, P = F S. The report's route uses S on
    // the current faces (volume 1/3) instead of the Cauchy stress J^-1 F S F^T, so at a strain
    // of -0.375 the two differ by factors F_yy = 0.5 and 1/J = 2 per direction.
    const Tet f =
        tetNodalForces(exampleRestTet(), exampleCurrentTet(), lameParameters(kYoung, kPoisson));
    const Lame l = lameParameters(kYoung, kPoisson);
    const double sxx = l.lambda * -0.375;  // = S_zz
    const double syy = (l.lambda + 2 * l.mu) * -0.375;
    const double scale = 6e9;
    EXPECT_NEAR(f(0, 1), -(2.0 / 3.0) * sxx * 0.5, 1e-12 * scale);        // 2.083e9
    EXPECT_NEAR(f(1, 2), -(2.0 / 3.0) * 0.5 * syy * 0.5, 1e-12 * scale);  // 1.042e9
    EXPECT_NEAR(f(2, 3), -(2.0 / 3.0) * sxx, 1e-12 * scale);              // 4.166e9
    EXPECT_NEAR((f.col(0) + f.rightCols<3>().rowwise().sum()).norm(), 0.0, 1e-12 * scale);
    // With the true Cauchy stress the report's face-traction route gives these forces exactly.
    const Mat3 F = deformationGradient(exampleRestTet(), exampleCurrentTet());
    const Tet viaFaces = nodalForcesFromFaceForces(
        faceForces(exampleCurrentTet(), cauchyStress(F, secondPiolaKirchhoff(F, l))));
    EXPECT_NEAR(maxAbs(viaFaces - f), 0.0, 1e-12 * scale);
}

TEST(ContinuumProperties, RigidRotationAndTranslationGiveZeroStrainAndZeroForces) {
    const Tet rest = irregularRestTet();
    const Tet moved = applyAffine(someRotation(), Vec3(5, -3, 2), rest);
    const Lame l = lameParameters(kYoung, kPoisson);
    const Mat3 F = deformationGradient(rest, moved);
    EXPECT_NEAR(greenStrain(F).norm(), 0.0, 1e-14);
    // Relative to the force a unit strain would produce on this element.
    const double scale = (l.lambda + 2 * l.mu) * std::pow(tetVolume(rest), 2.0 / 3.0);
    EXPECT_LE(maxAbs(tetNodalForces(rest, moved, l)), 1e-12 * scale);
    EXPECT_LE(maxAbs(reportTetNodalForces(rest, moved, l)), 1e-12 * scale);
}

TEST(ContinuumProperties, NodalForcesSumToZeroAndExertNoTorque) {
    const Tet rest = irregularRestTet();
    const Tet current = applyAffine(someRotation() * someDeformation(), Vec3(1, 2, 3), rest);
    const Lame l = lameParameters(3.0e6, 0.35);
    for (const Tet& f :
         {tetNodalForces(rest, current, l), reportTetNodalForces(rest, current, l)}) {
        const double scale = maxAbs(f);
        ASSERT_GT(scale, 0.0);
        EXPECT_NEAR(f.rowwise().sum().norm(), 0.0, 1e-13 * scale);
        Vec3 torque = Vec3::Zero();
        for (int i = 0; i < 4; ++i) torque += Vec3(current.col(i)).cross(Vec3(f.col(i)));
        EXPECT_NEAR(torque.norm(), 0.0, 1e-12 * scale);
    }
}

TEST(ContinuumProperties, ForcesAreTheNegativeGradientOfTheStrainEnergy) {
    const Tet restTet = irregularRestTet();
    const TetRest rest = tetRest(restTet);
    const Tet current = applyAffine(someRotation() * someDeformation(), Vec3(0.3, 0, -1), restTet);
    const Lame l = lameParameters(1.0, 0.3);
    const Tet f = tetNodalForces(rest, current, l);
    const double h = 1e-6;
    Tet gradient;
    for (int i = 0; i < 4; ++i)
        for (int d = 0; d < 3; ++d) {
            Tet plus = current, minus = current;
            plus(d, i) += h;
            minus(d, i) -= h;
            gradient(d, i) =
                (tetStrainEnergy(rest, plus, l) - tetStrainEnergy(rest, minus, l)) / (2 * h);
        }
    EXPECT_LE(maxAbs(f + gradient), 1e-7 * maxAbs(f));
    // The report's route is not a gradient at this strain, which is why it is not the model.
    EXPECT_GT(maxAbs(reportTetNodalForces(restTet, current, l) + gradient), 1e-2 * maxAbs(f));
}

TEST(ContinuumProperties, FaceTractionsOfTheCauchyStressEqualTheEnergyConsistentForces) {
    const Tet rest = irregularRestTet();
    const Tet current = applyAffine(someRotation() * someDeformation(), Vec3(-2, 1, 0), rest);
    const Lame l = lameParameters(kYoung, kPoisson);
    const Mat3 F = deformationGradient(rest, current);
    const Mat3 sigma = cauchyStress(F, secondPiolaKirchhoff(F, l));
    EXPECT_TRUE(sigma.isApprox(sigma.transpose(), 1e-12));
    const Tet viaFaces = nodalForcesFromFaceForces(faceForces(current, sigma));
    const Tet direct = tetNodalForces(rest, current, l);
    EXPECT_LE(maxAbs(viaFaces - direct), 1e-10 * maxAbs(direct));
}

TEST(ContinuumProperties, EnergyConsistentForcesTurnWithTheBodyButTheReportShortcutDoesNot) {
    const Tet rest = irregularRestTet();
    const Tet strained = applyAffine(someDeformation(), Vec3::Zero(), rest);
    const Mat3 R = someRotation();
    const Tet turned = applyAffine(R, Vec3::Zero(), strained);
    const Lame l = lameParameters(3.0e6, 0.35);
    const Tet f = tetNodalForces(rest, strained, l);
    EXPECT_LE(maxAbs(tetNodalForces(rest, turned, l) - R * f), 1e-12 * maxAbs(f));
    // The report keeps S unrotated while the faces turn, so its forces point the wrong way.
    const Tet g = reportTetNodalForces(rest, strained, l);
    EXPECT_GT(maxAbs(reportTetNodalForces(rest, turned, l) - R * g), 0.1 * maxAbs(g));
}

TEST(ContinuumProperties, ReportShortcutAgreesWithTheModelAtSmallUnrotatedStrain) {
    const Tet rest = irregularRestTet();
    const Mat3 small = Mat3::Identity() + 1e-5 * (someDeformation() - Mat3::Identity());
    const Tet current = applyAffine(small, Vec3(1, 1, 1), rest);
    const Lame l = lameParameters(kYoung, 0.3);
    const Tet model = tetNodalForces(rest, current, l);
    EXPECT_LE(maxAbs(reportTetNodalForces(rest, current, l) - model), 1e-4 * maxAbs(model));
}
