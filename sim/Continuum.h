#pragma once
// Continuum mechanics of the seminar report (seeds/001_b1a2c3e9c54b18d5.txt): deformation
// gradient of a linear tetrahedron (eqs. 3.1-3.2), Green strain (eq. 2.6), isotropic Hooke's
// law (eq. 2.8) and nodal forces (eqs. 3.3, 3.9-3.10). It is the FEM reference the particle
// solvers are compared against, so it favours plain, checkable formulas over speed.
//
// Two force routes live here on purpose:
//  - tetNodalForces: the St. Venant-Kirchhoff element, f = -V P Dm^-T. It is the exact negative
//    gradient of the strain energy V Psi(E), so it conserves energy and is rotation-invariant.
//  - reportTetNodalForces: the report's procedure, which plugs the stress computed from the
//    Green strain (really the second Piola-Kirchhoff stress S) into the current-configuration
//    face tractions A sigma n. It reproduces the printed example but is not energy-consistent
//    at large strain and not rotation-invariant (S stays unrotated while the faces turn); the
//    two routes agree to first order in the strain only for an unrotated element.
// Feeding the true Cauchy stress J^-1 F S F^T into the face-traction route gives back
// tetNodalForces exactly, which is how the tests tie the two together.
//
// Tetrahedra are 3x4 matrices whose columns are the vertices x0..x3. Nodal forces use the same
// layout: column i is the force the element exerts on vertex i.

#include <Eigen/Core>
#include <array>

namespace rend::sim::continuum {

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;
using Tet = Eigen::Matrix<double, 3, 4>;

/// Lamé parameters of an isotropic linear material.
struct Lame {
    double lambda = 0.0;
    double mu = 0.0;
};

/// lambda = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu)); the same material as the
/// Voigt matrix of eq. 2.8. Throws std::invalid_argument outside -1 < nu < 1/2 or for E <= 0.
Lame lameParameters(double youngsModulus, double poissonRatio);

/// [x1 - x0, x2 - x0, x3 - x0]: the tetrahedron translated so that vertex 0 is the origin.
Mat3 edgeMatrix(const Tet& tet);

/// F = Ds Dm^-1 with Ds, Dm the current and rest edge matrices.
Mat3 deformationGradient(const Tet& restTet, const Tet& currentTet);

/// E = (F^T F - I) / 2.
Mat3 greenStrain(const Mat3& F);

/// Hooke's law in tensor form, S = lambda tr(E) I + 2 mu E (St. Venant-Kirchhoff when E is
/// the Green strain). Equal to eq. 2.8 with engineering shear strains 2 E_ij in the Voigt
/// vector.
Mat3 hookeStress(const Mat3& strain, const Lame& lame);

/// Second Piola-Kirchhoff stress S of a St. Venant-Kirchhoff material at F.
Mat3 secondPiolaKirchhoff(const Mat3& F, const Lame& lame);

/// First Piola-Kirchhoff stress P = F S.
Mat3 firstPiolaKirchhoff(const Mat3& F, const Lame& lame);

/// Cauchy stress sigma = J^-1 F S F^T, J = det F.
Mat3 cauchyStress(const Mat3& F, const Mat3& S);

/// Strain-energy density per rest volume, Psi = lambda/2 tr(E)^2 + mu E:E.
double strainEnergyDensity(const Mat3& strain, const Lame& lame);

/// Unsigned volume |det(edgeMatrix)| / 6.
double tetVolume(const Tet& tet);

/// What the element needs from its rest shape, computed once per element.
struct TetRest {
    Mat3 restEdgesInverse = Mat3::Identity();  ///< Dm^-1
    double restVolume = 0.0;                   ///< V
};
TetRest tetRest(const Tet& restTet);

/// V Psi(E(F)): the element's stored elastic energy.
double tetStrainEnergy(const TetRest& rest, const Tet& currentTet, const Lame& lame);

/// St. Venant-Kirchhoff nodal forces: H = -V P Dm^-T gives vertices 1..3 as its columns,
/// vertex 0 gets minus their sum. Equals -d(V Psi)/dx.
Tet tetNodalForces(const TetRest& rest, const Tet& currentTet, const Lame& lame);
Tet tetNodalForces(const Tet& restTet, const Tet& currentTet, const Lame& lame);

/// A face of a tetrahedron; face k is the one opposite vertex k (the report's f_123, f_023,
/// f_013, f_012 are faces 0, 1, 2, 3).
struct TetFace {
    double area = 0.0;
    Vec3 inwardNormal = Vec3::Zero();  ///< unit, pointing towards vertex k as in eq. 3.9
};
std::array<TetFace, 4> tetFaces(const Tet& tet);

/// Column k: the face force A sigma n of face k (eq. 3.3) with the inward normal, i.e. the push
/// of the element's stress on that face.
Tet faceForces(const Tet& currentTet, const Mat3& sigma);

/// Each face force shared equally by its three vertices (eq. 3.10): vertex i gets one third of
/// the forces of the three faces that contain it.
Tet nodalForcesFromFaceForces(const Tet& faceForceColumns);

/// The report's procedure (Section 3): sigma := hookeStress(greenStrain(F)) applied on the
/// current faces, then shared among vertices.
Tet reportTetNodalForces(const Tet& restTet, const Tet& currentTet, const Lame& lame);

}  // namespace rend::sim::continuum
