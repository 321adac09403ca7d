#include "sim/FemCst.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

#include "sim/Parallel.h"

namespace rend::sim {

void triangleIncidence(const std::vector<std::array<int, 3>>& triangles, int particleCount,
                       std::vector<int>& offsets, std::vector<int>& corners) {
    offsets.assign(particleCount + 1, 0);
    for (const auto& t : triangles)
        for (int v : t) ++offsets[v + 1];
    for (int i = 0; i < particleCount; ++i) offsets[i + 1] += offsets[i];
    corners.assign(offsets.back(), 0);
    std::vector<int> fill(offsets.begin(), offsets.end() - 1);
    for (int t = 0; t < int(triangles.size()); ++t)
        for (int c = 0; c < 3; ++c) corners[fill[triangles[t][c]]++] = 3 * t + c;
}

FemCst::FemCst(const Lattice& lattice, const MaterialParams& material, double thickness,
               double criticalStrain)
    : thickness_(thickness),
      criticalStrain_(criticalStrain),
      expansion_(material.expansion),
      stiffnessLoss_(material.stiffnessLoss),
      strengthLoss_(material.strengthLoss) {
    const double nu = material.poissonRatio;
    if (!(nu > -1.0 && nu < 0.5)) throw std::invalid_argument("fem_cst needs -1 < poisson < 0.5");
    lambda_ = material.youngsModulus * nu / (1.0 - nu * nu);
    mu_ = material.youngsModulus / (2.0 * (1.0 + nu));
    const auto& p = lattice.positions;
    for (int index = 0; index < int(lattice.triangles.size()); ++index) {
        const auto& t = lattice.triangles[index];
        // Rest edges in the triangle's own plane (u along edge 01), so curved rest shapes such
        // as the sphere work; St. Venant-Kirchhoff is isotropic, so the frame is free.
        const Eigen::Vector3d e1 = p[t[1]] - p[t[0]], e2 = p[t[2]] - p[t[0]];
        const Eigen::Vector3d u = e1.normalized();
        const Eigen::Vector3d w = e1.cross(e2).cross(e1).normalized();
        Eigen::Matrix2d Dm;
        Dm << e1.dot(u), e2.dot(u), e1.dot(w), e2.dot(w);
        const double area = 0.5 * std::abs(Dm.determinant());
        if (area <= 0.0) continue;  // a degenerate rest triangle carries nothing
        elements_.push_back({t, Dm.inverse(), area, index, {-1, -1, -1}});
    }
    findNeighbours();
    alive_.assign(elements_.size(), 1);
    triangleAlive_.assign(lattice.triangles.size(), 1);
    std::vector<std::array<int, 3>> kept;
    for (const Element& e : elements_) kept.push_back(e.v);
    triangleIncidence(kept, int(p.size()), cornerOffsets_, corners_);
    cornerForce_.resize(3 * elements_.size());
}

void FemCst::findNeighbours() {
    std::map<std::pair<int, int>, std::pair<int, int>> side;  // edge -> (element, side)
    for (int e = 0; e < int(elements_.size()); ++e)
        for (int s = 0; s < 3; ++s) {
            const auto key = std::minmax(elements_[e].v[(s + 1) % 3], elements_[e].v[(s + 2) % 3]);
            const auto [it, added] = side.try_emplace(key, e, s);
            if (added) continue;
            elements_[e].across[s] = it->second.first;
            elements_[it->second.first].across[it->second.second] = e;
        }
}

Eigen::Matrix<double, 3, 2> FemCst::deformationGradient(
    const Element& e, const std::vector<Eigen::Vector3d>& x) const {
    Eigen::Matrix<double, 3, 2> Ds;
    Ds.col(0) = x[e.v[1]] - x[e.v[0]];
    Ds.col(1) = x[e.v[2]] - x[e.v[0]];
    return Ds * e.restInverse;
}

Eigen::Matrix2d FemCst::greenStrain(int t, const std::vector<Eigen::Vector3d>& x) const {
    const Eigen::Matrix<double, 3, 2> F = deformationGradient(elements_[t], x);
    return 0.5 * (F.transpose() * F - Eigen::Matrix2d::Identity());
}

void FemCst::forces(const std::vector<Eigen::Vector3d>& x,
                    std::vector<Eigen::Vector3d>& force) const {
    const int elements = int(elements_.size());
#pragma omp parallel for schedule(static) if (elements >= kParallelThreshold)
    for (int t = 0; t < elements; ++t) {
        const Element& e = elements_[t];
        if (!alive_[t]) {
            cornerForce_[3 * t] = cornerForce_[3 * t + 1] = cornerForce_[3 * t + 2] =
                Eigen::Vector3d::Zero();
            continue;
        }
        // The thermal strain stretches the rest state isotropically by s = 1 + alpha theta:
        // Psi(F / s), whose derivative is P(F / s) / s.
        const double theta = thetaOf(e), stretch = 1.0 + expansion_ * theta;
        const Eigen::Matrix<double, 3, 2> F = deformationGradient(e, x) / stretch;
        const Eigen::Matrix2d E = 0.5 * (F.transpose() * F - Eigen::Matrix2d::Identity());
        const Eigen::Matrix2d S =
            std::max(0.0, 1.0 - stiffnessLoss_ * theta) *
            (lambda_ * E.trace() * Eigen::Matrix2d::Identity() + 2.0 * mu_ * E);
        const Eigen::Matrix<double, 3, 2> H =
            -e.restArea * thickness_ / stretch * F * S * e.restInverse.transpose();
        cornerForce_[3 * t + 1] = H.col(0);
        cornerForce_[3 * t + 2] = H.col(1);
        cornerForce_[3 * t] = -H.col(0) - H.col(1);
    }
    const int n = int(x.size());
#pragma omp parallel for schedule(static) if (n >= kParallelThreshold)
    for (int i = 0; i < n; ++i) {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (int k = cornerOffsets_[i]; k < cornerOffsets_[i + 1]; ++k)
            sum += cornerForce_[corners_[k]];
        force[i] = sum;
    }
}

std::vector<double> FemCst::stiffnessRowSums(int particleCount) const {
    // At rest the element stiffness is K_ab = A0 h B_a^T C B_b with B_a the gradient of vertex
    // a's shape function; |C| <= lambda* + 2 mu bounds each 2x2 block's norm by
    // A0 h (lambda* + 2 mu) |g_a| |g_b|, a row of the block by sqrt(2) times that; half of the
    // row sum over b is the k_i of Solver::stiffnessRowSums.
    std::vector<double> sums(particleCount, 0.0);
    for (const Element& e : elements_) {
        const Eigen::Vector2d g1 = e.restInverse.row(0).transpose();
        const Eigen::Vector2d g2 = e.restInverse.row(1).transpose();
        const Eigen::Vector2d g[3] = {-g1 - g2, g1, g2};
        const double total = g[0].norm() + g[1].norm() + g[2].norm();
        for (int a = 0; a < 3; ++a)
            sums[e.v[a]] += e.restArea * thickness_ * (lambda_ + 2.0 * mu_) * g[a].norm() * total *
                            std::sqrt(2.0) / 2.0;
    }
    return sums;
}

double FemCst::thetaOf(const Element& e) const {
    if (theta_.empty()) return 0.0;
    return (theta_[e.v[0]] + theta_[e.v[1]] + theta_[e.v[2]]) / 3.0;
}

void FemCst::erode(int t, std::vector<std::array<int, 2>>& apart) {
    alive_[t] = 0;
    triangleAlive_[elements_[t].triangle] = 0;
    for (int s = 0; s < 3; ++s) {  // a side comes apart once no living element holds it
        const int other = elements_[t].across[s];
        if (other >= 0 && alive_[other]) continue;
        apart.push_back({elements_[t].v[(s + 1) % 3], elements_[t].v[(s + 2) % 3]});
    }
}

std::vector<std::array<int, 2>> FemCst::fracture(const std::vector<Eigen::Vector3d>& x) {
    std::vector<std::array<int, 2>> apart;
    if (!std::isfinite(criticalStrain_)) return apart;
    for (int t = 0; t < int(elements_.size()); ++t) {
        if (!alive_[t]) continue;
        // Largest principal Green strain of the mechanical part against the critical
        // stretch's, (l^2 - 1) / 2, with l = 1 + eps_c weakened by theta.
        const double theta = thetaOf(elements_[t]);
        const double limit = criticalStrain_ * std::max(0.0, 1.0 - strengthLoss_ * theta);
        const double stretch = 1.0 + expansion_ * theta;
        const Eigen::Matrix2d E =
            0.5 * ((greenStrain(t, x) * 2.0 + Eigen::Matrix2d::Identity()) / (stretch * stretch) -
                   Eigen::Matrix2d::Identity());
        const double centre = 0.5 * E.trace();
        const double radius = std::hypot(0.5 * (E(0, 0) - E(1, 1)), E(0, 1));
        if (centre + radius > 0.5 * ((1 + limit) * (1 + limit) - 1)) erode(t, apart);
    }
    return apart;
}

bool FemCst::cut(const std::vector<std::array<int, 2>>& edges) {
    std::map<std::pair<int, int>, bool> isCut;
    for (const auto& [a, b] : edges) isCut[std::minmax(a, b)] = true;
    std::vector<std::array<int, 2>> unused;
    for (int t = 0; t < int(elements_.size()); ++t)
        for (int s = 0; s < 3 && alive_[t]; ++s)
            if (isCut.count(std::minmax(elements_[t].v[(s + 1) % 3], elements_[t].v[(s + 2) % 3])))
                erode(t, unused);
    return true;
}

double FemCst::strainEnergy(const std::vector<Eigen::Vector3d>& x) const {
    double sum = 0.0;
    for (int t = 0; t < int(elements_.size()); ++t) {
        if (!alive_[t]) continue;
        const double theta = thetaOf(elements_[t]), stretch = 1.0 + expansion_ * theta;
        const Eigen::Matrix2d E =
            0.5 * ((greenStrain(t, x) * 2.0 + Eigen::Matrix2d::Identity()) / (stretch * stretch) -
                   Eigen::Matrix2d::Identity());
        sum += elements_[t].restArea * thickness_ * std::max(0.0, 1.0 - stiffnessLoss_ * theta) *
               (0.5 * lambda_ * E.trace() * E.trace() + mu_ * (E.array() * E.array()).sum());
    }
    return sum;
}

}  // namespace rend::sim
