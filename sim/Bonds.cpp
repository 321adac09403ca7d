#include "sim/Bonds.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

namespace rend::sim {
namespace {

// Uniform hash grid with cells of the horizon's size: a family lies in the 3x3 block of cells.
class CellGrid {
public:
    CellGrid(std::span<const Eigen::Vector3d> points, double cell) : cell_(cell) {
        for (int i = 0; i < int(points.size()); ++i) cells_[key(cellOf(points[i]))].push_back(i);
    }

    template <class Visit>
    void forNeighbourCells(const Eigen::Vector3d& p, Visit visit) const {
        const Eigen::Vector2i c = cellOf(p);
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                auto it = cells_.find(key({c.x() + dx, c.y() + dy}));
                if (it != cells_.end()) visit(it->second);
            }
    }

private:
    Eigen::Vector2i cellOf(const Eigen::Vector3d& p) const {
        return {int(std::floor(p.x() / cell_)), int(std::floor(p.y() / cell_))};
    }
    static std::int64_t key(const Eigen::Vector2i& c) {
        return (std::int64_t(c.x()) << 32) ^ std::int64_t(std::uint32_t(c.y()));
    }
    double cell_;
    std::unordered_map<std::int64_t, std::vector<int>> cells_;
};

}  // namespace

BondFamilies buildBondFamilies(std::span<const Eigen::Vector3d> rest, double horizon) {
    const int n = int(rest.size());
    // The tolerance keeps bonds at exactly R (e.g. R = 1.0 dx) in the family.
    const double reach = horizon * (1.0 + 1e-9);
    CellGrid grid(rest, horizon);
    std::vector<std::vector<int>> family(n);
#pragma omp parallel for schedule(static)
    for (int i = 0; i < n; ++i) {
        grid.forNeighbourCells(rest[i], [&](const std::vector<int>& cell) {
            for (int j : cell)
                if (j != i && (rest[j] - rest[i]).norm() <= reach) family[i].push_back(j);
        });
        std::sort(family[i].begin(), family[i].end());
    }
    BondFamilies bonds;
    bonds.offsets.assign(n + 1, 0);
    for (int i = 0; i < n; ++i) bonds.offsets[i + 1] = bonds.offsets[i] + int(family[i].size());
    const std::size_t m = std::size_t(bonds.offsets[n]);
    bonds.partners.resize(m);
    bonds.restLength.resize(m);
    bonds.weight.resize(m);
    for (int i = 0; i < n; ++i) {
        int b = bonds.offsets[i];
        for (int j : family[i]) {
            const double length = (rest[j] - rest[i]).norm();
            bonds.partners[b] = j;
            bonds.restLength[b] = length;
            bonds.weight[b] = std::max(0.0, 1.0 - length / horizon);
            ++b;
        }
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
