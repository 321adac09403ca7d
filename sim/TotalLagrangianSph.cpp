#include "sim/TotalLagrangianSph.h"

#include <Eigen/LU>
#include <cmath>
#include <stdexcept>

#include "sim/Bonds.h"
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

TotalLagrangianSph::TotalLagrangianSph(const Lattice& lattice, double dx, double youngsModulus,
                                       double poissonRatio, double thickness)
    : thickness_(thickness) {
    if (!(poissonRatio > -1.0 && poissonRatio < 0.5))
        throw std::invalid_argument("sph needs -1 < poisson < 0.5");
    lambda_ = youngsModulus * poissonRatio / (1.0 - poissonRatio * poissonRatio);
    mu_ = youngsModulus / (2.0 * (1.0 + poissonRatio));
    const auto& X = lattice.positions;
    const int n = int(X.size());
    const double support = kSupport * dx;
    const BondFamilies family = buildBondFamilies(X, support);
    offsets_ = family.offsets;
    neighbours_ = family.partners;
    volume_.assign(n, lattice.particleArea);
    if (!lattice.areas.empty()) volume_ = lattice.areas;
    gradient_.resize(neighbours_.size());
    for (int i = 0; i < n; ++i) {
        Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
        for (int k = offsets_[i]; k < offsets_[i + 1]; ++k) {
            const int j = neighbours_[k];
            const Eigen::Vector2d d = (X[j] - X[i]).head<2>();
            gradient_[k] = volume_[j] * kernel(d.norm(), support) * d;
            A += d * gradient_[k].transpose();
        }
        if (std::abs(A.determinant()) < 1e-12 * std::pow(A.norm(), 2))
            throw std::invalid_argument("sph: a particle's neighbours do not span the plane");
        const Eigen::Matrix2d correction = A.inverse().transpose();
        for (int k = offsets_[i]; k < offsets_[i + 1]; ++k)
            gradient_[k] = correction * gradient_[k];
    }
    mirror_.resize(neighbours_.size());
    for (int i = 0; i < n; ++i)
        for (int k = offsets_[i]; k < offsets_[i + 1]; ++k)
            mirror_[k] = findBond(family, neighbours_[k], i);
    stress_.resize(n);
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
    for (int i = 0; i < n; ++i)
        stress_[i] = volume_[i] * thickness_ * firstPiola(deformationGradient(i, x));
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
        const Eigen::Matrix<double, 3, 2> F = deformationGradient(i, x);
        const Eigen::Matrix2d E = 0.5 * (F.transpose() * F - Eigen::Matrix2d::Identity());
        sum += volume_[i] * thickness_ *
               (0.5 * lambda_ * E.trace() * E.trace() + mu_ * (E.array() * E.array()).sum());
    }
    return sum;
}

}  // namespace rend::sim
