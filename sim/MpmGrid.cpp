#include "sim/MpmGrid.h"

#include <array>
#include <cmath>
#include <stdexcept>

#include "sim/Parallel.h"

namespace rend::sim {
namespace {

constexpr int kBias = 1 << 20;  // node coordinates in [-2^20, 2^20) pack into 21 bits each
constexpr double kReach = double(kBias - 4);

std::uint64_t packKey(const Eigen::Vector3i& c) {
    return (std::uint64_t(c.x() + kBias) << 42) | (std::uint64_t(c.y() + kBias) << 21) |
           std::uint64_t(c.z() + kBias);
}

Eigen::Vector3i unpackKey(std::uint64_t key) {
    const std::uint64_t mask = (1u << 21) - 1;
    return {int((key >> 42) & mask) - kBias, int((key >> 21) & mask) - kBias,
            int(key & mask) - kBias};
}

std::uint64_t mixed(std::uint64_t k) {  // a 64-bit finaliser, so neighbouring keys spread
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdULL;
    k ^= k >> 33;
    k *= 0xc4ceb3f99cd5a2bdULL;
    return k ^ (k >> 33);
}

/// The quadratic B-spline's three weights along one axis, at frac = x / h - base in [0.5, 1.5).
std::array<double, 3> splineWeights(double frac) {
    const double a = 1.5 - frac, b = frac - 1.0, c = frac - 0.5;
    return {0.5 * a * a, 0.75 - b * b, 0.5 * c * c};
}

/// w_ip for the 27 nodes of a stencil, in (a, b, c) order, c fastest.
std::array<double, 27> stencilWeights(const Eigen::Vector3d& frac) {
    const auto wx = splineWeights(frac.x()), wy = splineWeights(frac.y()),
               wz = splineWeights(frac.z());
    std::array<double, 27> w{};
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
            for (int c = 0; c < 3; ++c) w[9 * a + 3 * b + c] = wx[a] * wy[b] * wz[c];
    return w;
}

}  // namespace

MpmGrid::MpmGrid(double spacing) : h_(spacing) {
    if (!(spacing > 0.0) || !std::isfinite(spacing))
        throw std::invalid_argument("the MPM grid's spacing must be positive and finite");
    keys_.assign(1024, 0);
    ids_.assign(1024, -1);
    stamps_.assign(1024, 0);
}

void MpmGrid::grow() {
    const std::size_t size = keys_.size() * 2;
    std::vector<std::uint64_t> keys(size, 0);
    std::vector<int> ids(size, -1);
    std::vector<std::uint32_t> stamps(size, 0);
    for (std::size_t s = 0; s < keys_.size(); ++s) {
        if (stamps_[s] != stamp_) continue;
        std::size_t slot = mixed(keys_[s]) & (size - 1);
        while (stamps[slot] == stamp_) slot = (slot + 1) & (size - 1);
        keys[slot] = keys_[s], ids[slot] = ids_[s], stamps[slot] = stamp_;
    }
    keys_.swap(keys), ids_.swap(ids), stamps_.swap(stamps);
}

int MpmGrid::nodeAt(std::uint64_t key) {
    std::size_t mask = keys_.size() - 1;
    std::size_t slot = mixed(key) & mask;
    while (stamps_[slot] == stamp_) {
        if (keys_[slot] == key) return ids_[slot];
        slot = (slot + 1) & mask;
    }
    const int id = int(nodeMass_.size());
    keys_[slot] = key, ids_[slot] = id, stamps_[slot] = stamp_;
    nodeMass_.push_back(0.0);
    nodeMomentum_.push_back(Eigen::Vector3d::Zero());
    nodeCell_.push_back(unpackKey(key));
    if (2 * nodeMass_.size() > keys_.size()) grow();
    return id;
}

void MpmGrid::clearNodes() {
    if (++stamp_ == 0) {  // the stamps wrapped: every slot is free again
        std::fill(stamps_.begin(), stamps_.end(), 0);
        stamp_ = 1;
    }
    nodeMass_.clear(), nodeMomentum_.clear(), nodeCell_.clear();
    std::fill(numbered_.begin(), numbered_.end(), 0);
}

void MpmGrid::buildStencils(std::span<const Eigen::Vector3d> x,
                            std::span<const std::uint8_t> onGrid) {
    const int n = int(x.size());
    if (int(numbered_.size()) != n) {
        base_.assign(n, Eigen::Vector3i::Zero());
        numbered_.assign(n, 0);
        nodes_.assign(27 * std::size_t(n), 0);
    }
    if (transfers_++ % kRenumberEvery == 0) clearNodes();
    stencil_.clear();
    for (int p = 0; p < n; ++p) {
        const Eigen::Vector3d scaled = x[p] / h_;
        if (!onGrid[p] || !scaled.allFinite() || scaled.cwiseAbs().maxCoeff() > kReach) continue;
        const Eigen::Vector3d low = (scaled.array() - 0.5).floor().matrix();
        const Eigen::Vector3i base = low.cast<int>();
        stencil_.push_back({scaled - low, p});
        if (numbered_[p] && base == base_[p]) continue;
        base_[p] = base, numbered_[p] = 1;
        for (int k = 0; k < 27; ++k)
            nodes_[27 * std::size_t(p) + k] =
                nodeAt(packKey(base + Eigen::Vector3i(k / 9, k / 3 % 3, k % 3)));
    }
    std::fill(nodeMass_.begin(), nodeMass_.end(), 0.0);
    std::fill(nodeMomentum_.begin(), nodeMomentum_.end(), Eigen::Vector3d::Zero());
}

void MpmGrid::particleToGrid(std::span<const double> mass, std::span<const Eigen::Vector3d> v,
                             std::span<const Eigen::Matrix3d> affine) {
    for (const Stencil& s : stencil_) {
        const int p = s.particle;
        const std::array<double, 27> w = stencilWeights(s.frac);
        const Eigen::Matrix3d affineH = affine[p] * h_;  // C_p (x_i - x_p), offsets in h
        const Eigen::Vector3d atParticle = v[p] - affineH * s.frac;
        const int* nodes = &nodes_[27 * std::size_t(p)];
        for (int k = 0; k < 27; ++k) {
            const double wm = w[k] * mass[p];
            nodeMass_[nodes[k]] += wm;
            nodeMomentum_[nodes[k]] +=
                wm * (atParticle + (k / 9) * affineH.col(0) + (k / 3 % 3) * affineH.col(1) +
                      (k % 3) * affineH.col(2));
        }
    }
}

// v_p = sum w v_i and C_p = 4 / h sum w v_i o^T (o = (a, b, c) - frac, in cells): the sums
// over (a, b, c) are the columns, less v_p frac^T.
void MpmGrid::nodeVelocities(const NodeCollision& collide) {
    const int nodeCount = int(nodeMass_.size());
    forEachIndex(nodeCount >= kParallelThreshold, 0, nodeCount, [&](int i) {
        if (nodeMass_[i] <= 0.0) return;
        nodeMomentum_[i] /= nodeMass_[i];
        if (collide) collide(h_ * nodeCell_[i].cast<double>(), nodeMomentum_[i]);
    });
}

void MpmGrid::gridToParticle(std::span<Eigen::Vector3d> v, std::span<Eigen::Matrix3d> affine) {
    const int count = int(stencil_.size());
    const double toAffine = 4.0 / h_;
    forEachIndex(count >= kParallelThreshold, 0, count, [&](int q) {
        const Stencil& s = stencil_[q];
        const std::array<double, 27> w = stencilWeights(s.frac);
        const int* nodes = &nodes_[27 * std::size_t(s.particle)];
        Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
        Eigen::Matrix3d moment = Eigen::Matrix3d::Zero();
        for (int k = 0; k < 27; ++k) {
            const Eigen::Vector3d wv = w[k] * nodeMomentum_[nodes[k]];
            velocity += wv;
            moment.col(0) += (k / 9) * wv;
            moment.col(1) += (k / 3 % 3) * wv;
            moment.col(2) += (k % 3) * wv;
        }
        v[s.particle] = velocity;
        affine[s.particle] = toAffine * (moment - velocity * s.frac.transpose());
    });
}

void MpmGrid::transfer(std::span<const Eigen::Vector3d> x, std::span<const double> mass,
                       std::span<const std::uint8_t> onGrid, std::span<Eigen::Vector3d> v,
                       std::span<Eigen::Matrix3d> affine, const NodeCollision& collide) {
    buildStencils(x, onGrid);
    particleToGrid(mass, v, affine);
    nodeVelocities(collide);
    gridToParticle(v, affine);
}

double MpmGrid::gridMass() const {
    double total = 0.0;
    for (const double m : nodeMass_) total += m;
    return total;
}

Eigen::Vector3d MpmGrid::gridMomentum() const {
    Eigen::Vector3d total = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < nodeMass_.size(); ++i) total += nodeMass_[i] * nodeMomentum_[i];
    return total;  // the momenta are velocities by now: times the mass again
}

}  // namespace rend::sim
