#include "sim/ParticleLevelSet.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <utility>

#include "sim/Lattice.h"

namespace rend::sim {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

int bondBetween(std::span<const int> offsets, std::span<const int> partners, int i, int j) {
    for (int b = offsets[i]; b < offsets[i + 1]; ++b)
        if (partners[b] == j) return b;
    return -1;
}

}  // namespace

ParticleLevelSet::ParticleLevelSet(const SheetParams& sheet, std::span<const Eigen::Vector3d> rest,
                                   std::span<const std::array<int, 3>> triangles,
                                   std::span<const int> bondOffsets,
                                   std::span<const int> bondPartners)
    : dx_(sheet.dx), rest_(rest.begin(), rest.end()) {
    const int n = int(rest.size());
    // The lattice edges of every particle, each once per end, in a fixed order.
    std::vector<std::vector<int>> ends(n);
    for (const auto& t : triangles)
        for (int k = 0; k < 3; ++k)
            ends[t[k]].push_back(t[(k + 1) % 3]), ends[t[(k + 1) % 3]].push_back(t[k]);
    neighbourOffsets_.assign(n + 1, 0);
    for (int i = 0; i < n; ++i) {
        std::sort(ends[i].begin(), ends[i].end());
        ends[i].erase(std::unique(ends[i].begin(), ends[i].end()), ends[i].end());
        for (int j : ends[i])
            neighbours_.push_back({j, bondBetween(bondOffsets, bondPartners, i, j)});
        neighbourOffsets_[i + 1] = int(neighbours_.size());
    }
    const double band = kBand * dx_;
    phi_.resize(n);
    for (int i = 0; i < n; ++i) phi_[i] = std::max(outlineDistance(sheet, rest[i]), -band);
    GhostBand ghosts = ghostBand(sheet);
    restGhost_ = std::move(ghosts.sites);
    band_ = std::move(ghosts.triangles);
    ghostPhi_.resize(restGhost_.size());
    for (std::size_t g = 0; g < restGhost_.size(); ++g)
        ghostPhi_[g] = outlineDistance(sheet, restGhost_[g]);
    // Each ghost's anchor: the nearest particle it shares a band triangle with (the lowest
    // numbered among equals).
    anchor_.assign(restGhost_.size(), -1);
    for (const auto& t : band_)
        for (int c : t) {
            if (c < n) continue;
            int& a = anchor_[c - n];
            for (int p : t) {
                if (p >= n) continue;
                const double d = (rest[p] - restGhost_[c - n]).squaredNorm();
                if (a < 0 || d < (rest[a] - restGhost_[c - n]).squaredNorm() ||
                    (d == (rest[a] - restGhost_[c - n]).squaredNorm() && p < a))
                    a = p;
            }
        }
    ghost_ = restGhost_;
    bandKept_.assign(band_.size(), 1);
    findSupports();
}

// Each ghost's support, fixed at rest: its anchor and the anchor's lattice neighbours, weighted
// by 1 - r / 2dx in rest distance from the ghost's site (those at 2 dx or more left out).
void ParticleLevelSet::findSupports() {
    const double reach = 2.0 * dx_;
    supportOffsets_.assign(1, 0);
    for (std::size_t g = 0; g < restGhost_.size(); ++g) {
        const int a = anchor_[g];
        auto add = [&](int p, int bond) {
            const double w = 1.0 - (rest_[p] - restGhost_[g]).norm() / reach;
            if (w > 0.0) support_.push_back({p, bond, w});
        };
        add(a, -1);
        for (const Neighbour& k : neighbours(a)) add(k.particle, k.bond);
        supportOffsets_.push_back(int(support_.size()));
    }
}

bool ParticleLevelSet::joined(int i, int j, std::span<const std::uint8_t> alive) const {
    if (i == j) return true;
    for (const Neighbour& k : neighbours(i))
        if (k.particle == j) return k.bond < 0 || alive[k.bond];
    return false;
}

bool ParticleLevelSet::nearlyJoined(int i, int j, std::span<const std::uint8_t> alive) const {
    if (joined(i, j, alive)) return true;
    for (const Neighbour& k : neighbours(i))
        if ((k.bond < 0 || alive[k.bond]) && joined(k.particle, j, alive)) return true;
    return false;
}

void ParticleLevelSet::keepBand(std::span<const std::uint8_t> alive) {
    const int n = int(phi_.size());
    for (std::size_t t = 0; t < band_.size(); ++t) {
        const auto& c = band_[t];
        bool kept = true;
        for (int a = 0; a < 3 && kept; ++a) {
            if (c[a] >= n) {  // its anchor is a corner or joined to one
                const int anchor = anchor_[c[a] - n];
                bool near = false;
                for (int p : c) near = near || (p < n && nearlyJoined(anchor, p, alive));
                kept = near;
                continue;
            }
            for (int b = a + 1; b < 3; ++b)
                if (c[b] < n) kept = kept && joined(c[a], c[b], alive);
        }
        bandKept_[t] = kept;
    }
}

bool ParticleLevelSet::deformation(int a, std::span<const Eigen::Vector3d> x,
                                   std::span<const std::uint8_t> alive, Eigen::Matrix3d& F) const {
    Eigen::Matrix3d moved = Eigen::Matrix3d::Zero(), spread = Eigen::Matrix3d::Zero();
    for (const Neighbour& k : neighbours(a)) {
        if (k.bond >= 0 && !alive[k.bond]) continue;
        const Eigen::Vector3d r = rest_[k.particle] - rest_[a];
        moved += (x[k.particle] - x[a]) * r.transpose();
        spread += r * r.transpose();
    }
    // The flat rest plane's normal, scaled like the spread, makes it invertible; the offsets F
    // maps lie in the plane, so it maps nothing.
    const double scale = 0.5 * spread.trace();
    if (!(scale > 0.0)) return false;
    spread(2, 2) += scale;
    if (!(spread.determinant() > 1e-3 * scale * scale * scale)) return false;
    F = moved * spread.inverse();
    return true;
}

void ParticleLevelSet::placeGhosts(std::span<const Eigen::Vector3d> x,
                                   std::span<const std::uint8_t> alive) {
    for (std::size_t g = 0; g < ghost_.size(); ++g) {
        const int a = anchor_[g];
        Eigen::Matrix3d F;
        if (deformation(a, x, alive, F)) ghost_[g] = x[a] + F * (restGhost_[g] - rest_[a]);
    }
}

void ParticleLevelSet::start(std::span<const Eigen::Vector3d> x,
                             std::span<const std::uint8_t> alive) {
    keepBand(alive);
    reinitialise(x, alive);
}

void ParticleLevelSet::advance(std::span<const Eigen::Vector3d> x,
                               std::span<const Eigen::Vector3d> v,
                               std::span<const std::uint8_t> alive, std::size_t broken, double dt,
                               long step) {
    for (std::size_t g = 0; g < ghost_.size(); ++g) {
        double total = 0.0;
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (int s = supportOffsets_[g]; s < supportOffsets_[g + 1]; ++s) {
            const Support& k = support_[s];
            if (k.bond >= 0 && !alive[k.bond]) continue;
            sum += k.weight * v[k.particle];
            total += k.weight;
        }
        if (total > 0.0) ghost_[g] += dt * sum / total;
    }
    if (broken != brokenSeen_) keepBand(alive), brokenSeen_ = broken;
    if (step % kReinitialiseEvery == 0) reinitialise(x, alive);
}

void ParticleLevelSet::offer(int i, const Segment& zero, std::span<const Eigen::Vector3d> x) {
    const double d = zero.distance(x[i]);
    if (distance_[i] == kInfinity) touched_.push_back(i);
    if (d < distance_[i]) distance_[i] = d, closest_[i] = zero;
}

void ParticleLevelSet::findZeroSet(std::span<const Eigen::Vector3d> x,
                                   std::span<const std::uint8_t> alive) {
    const int n = int(phi_.size());
    // The outline's: the segment through each kept band triangle between the crossings on its
    // particle-ghost edges, which its particles measure their distance to and hold.
    for (std::size_t t = 0; t < band_.size(); ++t) {
        if (!bandKept_[t]) continue;
        std::array<Eigen::Vector3d, 2> crossing;
        int count = 0;
        for (int k = 0; k < 3; ++k) {
            int i = band_[t][k], g = band_[t][(k + 1) % 3];
            if ((i < n) == (g < n)) continue;
            if (i >= n) std::swap(i, g);
            g -= n;
            if (!(ghostPhi_[g] > 0.0) || phi_[i] > 0.0 || count == 2) continue;
            const double s = phi_[i] / (phi_[i] - ghostPhi_[g]);
            crossing[count++] = x[i] + s * (ghost_[g] - x[i]);
        }
        if (count < 2) continue;
        for (int i : band_[t])
            if (i < n) offer(i, {crossing[0], crossing[1]}, x), holds_[i] = 1;
    }
    // Each crack's: a point on both sides of every broken lattice edge.
    if (brokenSeen_ == 0) return;
    for (int i = 0; i < n; ++i)
        for (const Neighbour& k : neighbours(i)) {
            if (k.bond < 0 || alive[k.bond]) continue;
            const Eigen::Vector3d r = x[k.particle] - x[i];
            const double length = r.norm();
            const Eigen::Vector3d direction =
                length > 0.0 ? Eigen::Vector3d(r / length)
                             : Eigen::Vector3d((rest_[k.particle] - rest_[i]).normalized());
            const Eigen::Vector3d lip =
                x[i] + 0.5 * (rest_[k.particle] - rest_[i]).norm() * direction;
            offer(i, {lip, lip}, x);
        }
}

void ParticleLevelSet::reinitialise(std::span<const Eigen::Vector3d> x,
                                    std::span<const std::uint8_t> alive) {
    placeGhosts(x, alive);
    const int n = int(phi_.size());
    if (distance_.size() != std::size_t(n)) {
        distance_.assign(n, kInfinity);
        closest_.resize(n);
        holds_.assign(n, 0);
    }
    findZeroSet(x, alive);
    // Closest points handed on through intact lattice edges, nearest first (serial: the same
    // bits whatever the thread count).
    const double band = kBand * dx_;
    using Entry = std::pair<double, int>;
    std::priority_queue<Entry, std::vector<Entry>, std::greater<>> front;
    for (int i : touched_)
        if (distance_[i] < band) front.emplace(distance_[i], i);
    while (!front.empty()) {
        const auto [d, i] = front.top();
        front.pop();
        if (d > distance_[i]) continue;
        for (const Neighbour& k : neighbours(i)) {
            if (k.bond >= 0 && !alive[k.bond]) continue;
            const double e = closest_[i].distance(x[k.particle]);
            if (e < distance_[k.particle] && e < band) {
                if (distance_[k.particle] == kInfinity) touched_.push_back(k.particle);
                distance_[k.particle] = e, closest_[k.particle] = closest_[i];
                front.emplace(e, k.particle);
            }
        }
    }
    for (int i = 0; i < n; ++i)
        if (!holds_[i]) phi_[i] = -std::min(distance_[i], band);
    for (int i : touched_) distance_[i] = kInfinity, holds_[i] = 0;
    touched_.clear();
}

}  // namespace rend::sim
