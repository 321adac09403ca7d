#include "sim/Continuum.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <stdexcept>

namespace rend::sim::continuum {

Lame lameParameters(double youngsModulus, double poissonRatio) {
    // nu = 1/2 divides by zero in lambda; nu <= -1 makes mu non-positive.
    if (!(youngsModulus > 0.0) || !(poissonRatio > -1.0 && poissonRatio < 0.5))
        throw std::invalid_argument("need E > 0 and -1 < nu < 1/2");
    const double nu = poissonRatio;
    return {youngsModulus * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            youngsModulus / (2.0 * (1.0 + nu))};
}

Mat3 edgeMatrix(const Tet& tet) { return tet.rightCols<3>().colwise() - tet.col(0); }

Mat3 deformationGradient(const Tet& restTet, const Tet& currentTet) {
    return edgeMatrix(currentTet) * edgeMatrix(restTet).inverse();
}

Mat3 greenStrain(const Mat3& F) { return 0.5 * (F.transpose() * F - Mat3::Identity()); }

Mat3 hookeStress(const Mat3& strain, const Lame& lame) {
    return lame.lambda * strain.trace() * Mat3::Identity() + 2.0 * lame.mu * strain;
}

Mat3 secondPiolaKirchhoff(const Mat3& F, const Lame& lame) {
    return hookeStress(greenStrain(F), lame);
}

Mat3 firstPiolaKirchhoff(const Mat3& F, const Lame& lame) {
    return F * secondPiolaKirchhoff(F, lame);
}

Mat3 cauchyStress(const Mat3& F, const Mat3& S) { return F * S * F.transpose() / F.determinant(); }

double strainEnergyDensity(const Mat3& strain, const Lame& lame) {
    const double trace = strain.trace();
    return 0.5 * lame.lambda * trace * trace + lame.mu * strain.squaredNorm();
}

double tetVolume(const Tet& tet) { return std::abs(edgeMatrix(tet).determinant()) / 6.0; }

TetRest tetRest(const Tet& restTet) {
    const Mat3 Dm = edgeMatrix(restTet);
    return {Dm.inverse(), std::abs(Dm.determinant()) / 6.0};
}

double tetStrainEnergy(const TetRest& rest, const Tet& currentTet, const Lame& lame) {
    const Mat3 F = edgeMatrix(currentTet) * rest.restEdgesInverse;
    return rest.restVolume * strainEnergyDensity(greenStrain(F), lame);
}

Tet tetNodalForces(const TetRest& rest, const Tet& currentTet, const Lame& lame) {
    const Mat3 F = edgeMatrix(currentTet) * rest.restEdgesInverse;
    // dF/dx_i for i = 1..3 is e (row i-1 of Dm^-1), so dW/dx_i = V P Dm^-T column i-1; vertex
    // 0 enters every edge with a minus sign, hence minus the sum.
    const Mat3 H =
        -rest.restVolume * firstPiolaKirchhoff(F, lame) * rest.restEdgesInverse.transpose();
    Tet forces;
    forces.rightCols<3>() = H;
    forces.col(0) = -H.rowwise().sum();
    return forces;
}

Tet tetNodalForces(const Tet& restTet, const Tet& currentTet, const Lame& lame) {
    return tetNodalForces(tetRest(restTet), currentTet, lame);
}

std::array<TetFace, 4> tetFaces(const Tet& tet) {
    std::array<TetFace, 4> faces;
    for (int k = 0; k < 4; ++k) {
        const Vec3 a = tet.col((k + 1) % 4);
        const Vec3 b = tet.col((k + 2) % 4);
        const Vec3 c = tet.col((k + 3) % 4);
        Vec3 n = (b - a).cross(c - a);
        const double twiceArea = n.norm();
        // The vertex order around the face depends on k and on the element's handedness, so
        // orient by the opposite vertex instead.
        if (n.dot(tet.col(k) - a) < 0.0) n = -n;
        faces[k] = {0.5 * twiceArea, twiceArea > 0.0 ? Vec3(n / twiceArea) : Vec3::Zero()};
    }
    return faces;
}

Tet faceForces(const Tet& currentTet, const Mat3& sigma) {
    const auto faces = tetFaces(currentTet);
    Tet forces;
    for (int k = 0; k < 4; ++k) forces.col(k) = faces[k].area * sigma * faces[k].inwardNormal;
    return forces;
}

Tet nodalForcesFromFaceForces(const Tet& faceForceColumns) {
    // Vertex i lies on every face except face i.
    const Vec3 total = faceForceColumns.rowwise().sum();
    Tet forces;
    for (int i = 0; i < 4; ++i) forces.col(i) = (total - faceForceColumns.col(i)) / 3.0;
    return forces;
}

Tet reportTetNodalForces(const Tet& restTet, const Tet& currentTet, const Lame& lame) {
    const Mat3 sigma = secondPiolaKirchhoff(deformationGradient(restTet, currentTet), lame);
    return nodalForcesFromFaceForces(faceForces(currentTet, sigma));
}

}  // namespace rend::sim::continuum
