#include "sim/Remesh.h"

#include <Eigen/Dense>
#include <cmath>

#include "sim/Parallel.h"

namespace rend::sim {

double m4Prime(double s) {
    s = std::abs(s);
    if (s < 1.0) return 1.0 - 2.5 * s * s + 1.5 * s * s * s;
    if (s < 2.0) return 0.5 * (1.0 - s) * (2.0 - s) * (2.0 - s);
    return 0.0;
}

Remesher::Remesher(std::span<const Eigen::Vector3d> rest, const BondFamilies& bonds, double h)
    : bonds_(bonds) {
    rest_.reserve(rest.size());
    for (const Eigen::Vector3d& x : rest) rest_.push_back(x.head<2>());
    weight_.resize(bonds.partners.size());
    for (int i = 0; i < int(rest_.size()); ++i)
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
            const Eigen::Vector2d d = (rest_[bonds.partners[b]] - rest_[i]) / h;
            weight_[b] = m4Prime(d.x()) * m4Prime(d.y());
        }
}

// Least squares of f_j ~ a + B (X_j - X_i) with weights W_ij (W_ii = 1): a from the 3x3 normal
// equations on the basis (1, dX, dY). Fewer than three neighbours in general position (a corner,
// a particle torn loose): the weighted mean, or the particle's own value.
Eigen::Vector3d Remesher::fitted(int i, std::span<const Eigen::Vector3d> f,
                                 std::span<const std::uint8_t> alive) const {
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Matrix3d rhs = Eigen::Matrix3d::Zero();  // columns: the basis' moments of f
    auto add = [&](const Eigen::Vector3d& basis, double w, const Eigen::Vector3d& value) {
        normal += w * basis * basis.transpose();
        rhs += w * basis * value.transpose();
    };
    add(Eigen::Vector3d(1, 0, 0), 1.0, f[i]);
    int used = 0;
    for (int b = bonds_.offsets[i]; b < bonds_.offsets[i + 1]; ++b) {
        if (!alive[b] || weight_[b] == 0.0) continue;
        const int j = bonds_.partners[b];
        const Eigen::Vector2d d = rest_[j] - rest_[i];
        add(Eigen::Vector3d(1, d.x(), d.y()), weight_[b], f[j]);
        ++used;
    }
    if (used < 3) return f[i];
    const Eigen::LDLT<Eigen::Matrix3d> solve(normal);
    if (solve.info() != Eigen::Success || solve.rcond() < 1e-8)
        return (rhs.row(0) / normal(0, 0)).transpose();
    return (solve.solve(rhs)).row(0).transpose();
}

void Remesher::remesh(std::span<Eigen::Vector3d> x, std::span<Eigen::Vector3d> v,
                      std::span<const double> mass, std::span<const std::uint8_t> alive,
                      std::span<const std::uint8_t> free) const {
    const int n = int(x.size());
    std::vector<Eigen::Vector3d> newX(x.begin(), x.end()), newV(v.begin(), v.end());
    forEachIndex(n >= kParallelThreshold, 0, n, [&](int i) {
        if (!free[i]) return;
        newX[i] = fitted(i, x, alive);
        newV[i] = fitted(i, v, alive);
    });
    // Hand the momentum the fit moved back evenly over the free particles, in index order.
    Eigen::Vector3d change = Eigen::Vector3d::Zero();
    double freeMass = 0.0;
    for (int i = 0; i < n; ++i) {
        if (!free[i]) continue;
        change += mass[i] * (newV[i] - v[i]);
        freeMass += mass[i];
    }
    const Eigen::Vector3d back =
        freeMass > 0.0 ? Eigen::Vector3d(change / freeMass) : Eigen::Vector3d::Zero();
    for (int i = 0; i < n; ++i)
        if (free[i]) x[i] = newX[i], v[i] = newV[i] - back;
}

}  // namespace rend::sim
