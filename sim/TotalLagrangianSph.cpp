#include "sim/TotalLagrangianSph.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sim/Fracture.h"
#include "sim/Parallel.h"

namespace rend::sim {
namespace {

constexpr double kSupport = 2.0;  ///< neighbours within this many dx

/// Wendland C2 in 2D, up to its constant (the correction A_i^-T absorbs any scale).
double kernel(double r, double support) {
    const double q = r / support;
    return q >= 1.0 ? 0.0 : std::pow(1.0 - q, 4) * (4.0 * q + 1.0);
}

}  // namespace

TotalLagrangianSph::TotalLagrangianSph(const Lattice& lattice, double dx,
                                       const MaterialParams& material, double thickness,
                                       std::span<const Notch> notches)
    : rest_(lattice.positions),
      support_(kSupport * dx),
      expansion_(material.expansion),
      stiffnessLoss_(material.stiffnessLoss),
      strengthLoss_(material.strengthLoss),
      thickness_(thickness) {
    const double nu = material.poissonRatio;
    if (!(nu > -1.0 && nu < 0.5)) throw std::invalid_argument("sph needs -1 < poisson < 0.5");
    lambda_ = material.youngsModulus * nu / (1.0 - nu * nu);
    mu_ = material.youngsModulus / (2.0 * (1.0 + nu));
    const int n = int(rest_.size());
    pairs_ = buildBondFamilies(rest_, support_);
    applyNotches(notches, rest_, pairs_);
    offsets_ = pairs_.offsets;
    neighbours_ = pairs_.partners;
    volume_.assign(n, lattice.particleArea);
    if (!lattice.areas.empty()) volume_ = lattice.areas;
    gradient_.resize(neighbours_.size());
    for (int i = 0; i < n; ++i) correctGradients(i);
    mirror_.resize(neighbours_.size());
    for (int i = 0; i < n; ++i)
        for (int k = offsets_[i]; k < offsets_[i + 1]; ++k)
            mirror_[k] = findBond(pairs_, neighbours_[k], i);
    stress_.resize(n);
}

void TotalLagrangianSph::correctGradients(int i) {
    Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
    for (int k = offsets_[i]; k < offsets_[i + 1]; ++k) {
        const Eigen::Vector2d d = (rest_[neighbours_[k]] - rest_[i]).head<2>();
        gradient_[k] =
            pairs_.alive[k]
                ? Eigen::Vector2d(volume_[neighbours_[k]] * kernel(d.norm(), support_) * d)
                : Eigen::Vector2d::Zero();
        A += d * gradient_[k].transpose();
    }
    const double size = A.norm();
    const bool spans = size > 0.0 && std::abs(A.determinant()) > 1e-6 * size * size;
    Eigen::Matrix2d correction = Eigen::Matrix2d::Zero();
    if (spans) correction = A.inverse().transpose();
    for (int k = offsets_[i]; k < offsets_[i + 1]; ++k) gradient_[k] = correction * gradient_[k];
}

Eigen::Matrix<double, 3, 2> TotalLagrangianSph::deformationGradient(
    int i, const std::vector<Eigen::Vector3d>& x) const {
    Eigen::Matrix<double, 3, 2> F = Eigen::Matrix<double, 3, 2>::Zero();
    for (int k = offsets_[i]; k < offsets_[i + 1]; ++k)
        F += (x[neighbours_[k]] - x[i]) * gradient_[k].transpose();
    return F;
}

Eigen::Matrix<double, 3, 2> TotalLagrangianSph::firstPiola(
    const Eigen::Matrix<double, 3, 2>& F) const {
    const Eigen::Matrix2d E = 0.5 * (F.transpose() * F - Eigen::Matrix2d::Identity());
    return F * (lambda_ * E.trace() * Eigen::Matrix2d::Identity() + 2.0 * mu_ * E);
}

void TotalLagrangianSph::forces(const std::vector<Eigen::Vector3d>& x,
                                std::vector<Eigen::Vector3d>& force) const {
    const int n = int(x.size());
#pragma omp parallel for schedule(static) if (n >= kParallelThreshold)
    for (int i = 0; i < n; ++i) {
        // Psi(F / s) with s = 1 + alpha theta: its derivative is P(F / s) / s.
        const double stretch = 1.0 + expansion_ * thetaAt(i);
        stress_[i] = volume_[i] * thickness_ * std::max(0.0, 1.0 - stiffnessLoss_ * thetaAt(i)) /
                     stretch * firstPiola(deformationGradient(i, x) / stretch);
    }
#pragma omp parallel for schedule(static) if (n >= kParallelThreshold)
    for (int i = 0; i < n; ++i) {
        Eigen::Vector2d own = Eigen::Vector2d::Zero();
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (int k = offsets_[i]; k < offsets_[i + 1]; ++k) {
            own += gradient_[k];
            sum -= stress_[neighbours_[k]] * gradient_[mirror_[k]];  // - V_j h P_j g_ji
        }
        force[i] = sum + stress_[i] * own;
    }
}

std::vector<double> TotalLagrangianSph::stiffnessRowSums(int particleCount) const {
    // As for the FEM: particle i's energy term is an "element" over i and its neighbours with
    // gradients g_ij and -sum_j g_ij; each adds sqrt(2)/2 V_i h (lambda* + 2 mu) |G_a| sum_b |G_b|
    // to its nodes' half row sums.
    std::vector<double> sums(particleCount, 0.0);
    for (int i = 0; i < particleCount; ++i) {
        Eigen::Vector2d own = Eigen::Vector2d::Zero();
        double total = 0.0;
        for (int k = offsets_[i]; k < offsets_[i + 1]; ++k) {
            own += gradient_[k];
            total += gradient_[k].norm();
        }
        total += own.norm();
        const double scale = std::sqrt(0.5) * volume_[i] * thickness_ * (lambda_ + 2.0 * mu_);
        sums[i] += scale * own.norm() * total;
        for (int k = offsets_[i]; k < offsets_[i + 1]; ++k)
            sums[neighbours_[k]] += scale * gradient_[k].norm() * total;
    }
    return sums;
}

double TotalLagrangianSph::strainEnergy(const std::vector<Eigen::Vector3d>& x) const {
    double sum = 0.0;
    for (int i = 0; i < int(x.size()); ++i) {
        const Eigen::Matrix<double, 3, 2> F =
            deformationGradient(i, x) / (1.0 + expansion_ * thetaAt(i));
        const Eigen::Matrix2d E = 0.5 * (F.transpose() * F - Eigen::Matrix2d::Identity());
        sum += volume_[i] * thickness_ * std::max(0.0, 1.0 - stiffnessLoss_ * thetaAt(i)) *
               (0.5 * lambda_ * E.trace() * E.trace() + mu_ * (E.array() * E.array()).sum());
    }
    return sum;
}

}  // namespace rend::sim
