#include "sim/Bonds.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>
#include <vector>

namespace rend::sim {
namespace {

// Cells of the horizon's size in x and y: a family lies in the 3x3 block of cells around its
// particle. A dense grid of the points' bounding cells where it is at most a few cells per point
// (a sheet), else a hash of the cells used.
class CellGrid {
public:
    CellGrid(std::span<const Eigen::Vector3d> points, double cell) : cell_(cell) {
        const int n = int(points.size());
        if (n == 0) return;
        Eigen::Vector2i lo = cellOf(points[0]), hi = lo;
        for (const Eigen::Vector3d& p : points) {
            lo = lo.cwiseMin(cellOf(p));
            hi = hi.cwiseMax(cellOf(p));
        }
        const double cells = (double(hi.x()) - lo.x() + 1.0) * (double(hi.y()) - lo.y() + 1.0);
        if (cells > 4.0 * n + 1024.0) {
            for (int i = 0; i < n; ++i) hashed_[key(cellOf(points[i]))].push_back(i);
            return;
        }
        low_ = lo, width_ = hi.x() - lo.x() + 1, height_ = hi.y() - lo.y() + 1;
        first_.assign(std::size_t(width_) * height_ + 1, 0);
        for (const Eigen::Vector3d& p : points) ++first_[denseOf(cellOf(p)) + 1];
        for (std::size_t c = 1; c < first_.size(); ++c) first_[c] += first_[c - 1];
        points_.resize(n);
        std::vector<int> next(first_.begin(), first_.end() - 1);
        for (int i = 0; i < n; ++i) points_[next[denseOf(cellOf(points[i]))]++] = i;
    }

    /// visit(begin, end) for the points of each of the nine cells around p's.
    template <class Visit>
    void forNeighbourCells(const Eigen::Vector3d& p, Visit visit) const {
        const Eigen::Vector2i c = cellOf(p);
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const Eigen::Vector2i at(c.x() + dx, c.y() + dy);
                if (first_.empty()) {
                    const auto it = hashed_.find(key(at));
                    if (it != hashed_.end())
                        visit(it->second.data(), it->second.data() + it->second.size());
                    continue;
                }
                const Eigen::Vector2i g = at - low_;
                if (g.x() < 0 || g.y() < 0 || g.x() >= width_ || g.y() >= height_) continue;
                const std::size_t d = denseOf(at);
                visit(points_.data() + first_[d], points_.data() + first_[d + 1]);
            }
    }

private:
    Eigen::Vector2i cellOf(const Eigen::Vector3d& p) const {
        return {int(std::floor(p.x() / cell_)), int(std::floor(p.y() / cell_))};
    }
    static std::int64_t key(const Eigen::Vector2i& c) {
        return (std::int64_t(c.x()) << 32) ^ std::int64_t(std::uint32_t(c.y()));
    }
    std::size_t denseOf(const Eigen::Vector2i& c) const {
        return std::size_t(c.y() - low_.y()) * width_ + std::size_t(c.x() - low_.x());
    }
    double cell_;
    Eigen::Vector2i low_ = Eigen::Vector2i::Zero();
    int width_ = 0, height_ = 0;
    std::vector<int> first_, points_;  ///< dense: per cell, CSR of the points (ascending)
    std::unordered_map<std::int64_t, std::vector<int>> hashed_;
};

}  // namespace

BondFamilies buildBondFamilies(std::span<const Eigen::Vector3d> rest, double horizon) {
    const int n = int(rest.size());
    // The tolerance keeps bonds at exactly R (e.g. R = 1.0 dx) in the family.
    const double reach = horizon * (1.0 + 1e-9);
    // Cells a little wider than the reach: two points within it never lie two cells apart,
    // even where a coordinate over the cell rounds below a whole number (with cells of the
    // horizon, a sheet's bonds at exactly R = 1 dx went missing where x / dx did: 0.29 / 0.01
    // is 28.999999999999996, 0.30 / 0.01 is 30).
    const CellGrid grid(rest, reach * (1.0 + 1e-9));
    BondFamilies bonds;
    bonds.offsets.assign(n + 1, 0);
    // Each thread's particles' partners (ascending) in one list of its own, joined in order: a
    // list per particle was a quarter of the final foil's set-up in allocations.
    std::vector<std::vector<int>> found;
#pragma omp parallel
    {
        const int threads = omp_get_num_threads(), thread = omp_get_thread_num();
#pragma omp single
        found.resize(threads);
        const int begin = int(std::int64_t(n) * thread / threads);
        const int end = int(std::int64_t(n) * (thread + 1) / threads);
        std::vector<int>& mine = found[thread];
        for (int i = begin; i < end; ++i) {
            const std::size_t start = mine.size();
            grid.forNeighbourCells(rest[i], [&](const int* first, const int* last) {
                for (const int* j = first; j != last; ++j)
                    if (*j != i && (rest[*j] - rest[i]).norm() <= reach) mine.push_back(*j);
            });
            std::sort(mine.begin() + std::ptrdiff_t(start), mine.end());
            bonds.offsets[i + 1] = int(mine.size() - start);
        }
    }
    for (int i = 0; i < n; ++i) bonds.offsets[i + 1] += bonds.offsets[i];
    const std::size_t m = std::size_t(bonds.offsets[n]);
    bonds.partners.resize(m);
    bonds.restLength.resize(m);
    bonds.weight.resize(m);
    std::size_t at = 0;
    for (const std::vector<int>& mine : found) {
        std::copy(mine.begin(), mine.end(), bonds.partners.begin() + std::ptrdiff_t(at));
        at += mine.size();
    }
#pragma omp parallel for schedule(static)
    for (int i = 0; i < n; ++i)
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
            const double length = (rest[bonds.partners[b]] - rest[i]).norm();
            bonds.restLength[b] = length;
            bonds.weight[b] = std::max(0.0, 1.0 - length / horizon);
        }
    return bonds;
}

BondPairs buildBondPairs(const BondFamilies& bonds) {
    const int n = bonds.particleCount();
    BondPairs pairs;
    pairs.upperBegin.resize(n);
    pairs.pairBegin.assign(n + 1, 0);
    pairs.pairOf.assign(bonds.directedCount(), -1);
    for (int i = 0; i < n; ++i) {
        const auto first = bonds.partners.begin() + bonds.offsets[i];
        const auto last = bonds.partners.begin() + bonds.offsets[i + 1];
        pairs.upperBegin[i] = int(std::upper_bound(first, last, i) - bonds.partners.begin());
        pairs.pairBegin[i + 1] = pairs.pairBegin[i] + bonds.offsets[i + 1] - pairs.upperBegin[i];
    }
    pairs.twin.assign(pairs.pairBegin[n], -1);
    for (int i = 0; i < n; ++i)
        for (int b = pairs.upperBegin[i]; b < bonds.offsets[i + 1]; ++b) {
            const int u = pairs.pairBegin[i] + b - pairs.upperBegin[i];
            const int lower = findBond(bonds, bonds.partners[b], i);
            if (lower < 0) throw std::logic_error("a bond has no copy at its other end");
            pairs.pairOf[b] = pairs.pairOf[lower] = u;
            pairs.twin[u] = lower;
        }
    return pairs;
}

}  // namespace rend::sim
