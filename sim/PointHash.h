#pragma once
// A spatial hash of points for fixed-radius neighbour queries (self-contact's searches).

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

namespace rend::sim {

/// Points hashed into cells of the query radius; near(x, f) calls f(k) for every point k
/// within the radius of x.
class PointHash {
public:
    PointHash(std::span<const Eigen::Vector3d> points, double radius) : cell_(radius) {
        const std::size_t n = points.size();
        std::uint32_t buckets = 1;
        while (buckets < 2 * n) buckets <<= 1;
        mask_ = buckets - 1;
        std::vector<std::uint32_t> bucket(n);
        std::vector<Eigen::Vector3i> cell(n);
        for (std::size_t i = 0; i < n; ++i) {
            cell[i] = cellOf(points[i]);
            bucket[i] = bucketOf(cell[i]);
        }
        start_.assign(std::size_t(buckets) + 1, 0);
        for (std::size_t i = 0; i < n; ++i) ++start_[bucket[i] + 1];
        for (std::uint32_t b = 0; b < buckets; ++b) start_[b + 1] += start_[b];
        items_.resize(n);
        cells_.resize(n);
        points_.resize(n);
        std::vector<int> fill(start_.begin(), start_.end() - 1);
        for (std::size_t i = 0; i < n; ++i) {
            const std::size_t at = std::size_t(fill[bucket[i]]++);
            items_[at] = int(i);
            cells_[at] = cell[i];
            points_[at] = points[i];
        }
    }

    /// Calls f(item) for every item within r of x, from the 27 cells about x. The items' points
    /// are stored in bucket order, so the scan reads memory in sequence.
    template <class F>
    void near(const Eigen::Vector3d& x, F&& f) const {
        const Eigen::Vector3i c = cellOf(x);
        const double r2 = cell_ * cell_;
        for (int z = -1; z <= 1; ++z)
            for (int y = -1; y <= 1; ++y)
                for (int w = -1; w <= 1; ++w) {
                    const Eigen::Vector3i cell = c + Eigen::Vector3i(w, y, z);
                    const std::uint32_t b = bucketOf(cell);
                    for (int s = start_[b]; s < start_[b + 1]; ++s)
                        if ((points_[std::size_t(s)] - x).squaredNorm() < r2 &&
                            cells_[std::size_t(s)] == cell)
                            f(items_[std::size_t(s)]);
                }
    }

private:
    Eigen::Vector3i cellOf(const Eigen::Vector3d& x) const {
        return (x / cell_).array().floor().cast<int>();
    }
    std::uint32_t bucketOf(const Eigen::Vector3i& c) const {
        const std::uint64_t h = std::uint64_t(std::int64_t(c.x())) * 73856093u ^
                                std::uint64_t(std::int64_t(c.y())) * 19349663u ^
                                std::uint64_t(std::int64_t(c.z())) * 83492791u;
        return std::uint32_t(h ^ (h >> 32)) & mask_;
    }

    double cell_;
    std::uint32_t mask_ = 0;
    std::vector<int> start_, items_;
    std::vector<Eigen::Vector3i> cells_;
    std::vector<Eigen::Vector3d> points_;
};

}  // namespace rend::sim
