#pragma once
// A spatial hash of points for fixed-radius neighbour queries (self-contact's searches).

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

namespace rend::sim {

/// Points hashed into cells twice the query radius wide; near(x, f) calls f(k) for every point k
/// within the radius of x. A query reads the cells the ball overlaps, one or two per axis (3.4 on
/// average, at most 8): few scattered reads of the bucket table, each a likely cache miss on a
/// large sheet, against a few more points read in sequence than cells of the radius would hold.
class PointHash {
public:
    PointHash(std::span<const Eigen::Vector3d> points, double radius)
        : radius_(radius), cell_(2.0 * radius) {
        const std::size_t n = points.size();
        std::uint32_t buckets = 1;
        while (buckets < n) buckets <<= 1;
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

    /// Calls f(item) for every item within the radius of x. The items' points are stored in
    /// bucket order, so the scan reads memory in sequence.
    template <class F>
    void near(const Eigen::Vector3d& x, F&& f) const {
        nearSlots(x, [&](int slot) { f(items_[std::size_t(slot)]); });
    }

    /// As near, but calls f(slot): the point's place in the hash's own order, in which the
    /// points are stored (item(slot) is its index), so data a query reads per point, copied
    /// into slot order, is read in sequence too.
    template <class F>
    void nearSlots(const Eigen::Vector3d& x, F&& f) const {
        // The cells the ball [x - r, x + r] overlaps: one or two per axis.
        const Eigen::Vector3i lo = cellOf(x - Eigen::Vector3d::Constant(radius_));
        const Eigen::Vector3i hi = cellOf(x + Eigen::Vector3d::Constant(radius_));
        const double r2 = radius_ * radius_;
        for (int z = lo.z(); z <= hi.z(); ++z)
            for (int y = lo.y(); y <= hi.y(); ++y)
                for (int w = lo.x(); w <= hi.x(); ++w) {
                    const Eigen::Vector3i cell(w, y, z);
                    const std::uint32_t b = bucketOf(cell);
                    for (int s = start_[b]; s < start_[b + 1]; ++s)
                        if ((points_[std::size_t(s)] - x).squaredNorm() < r2 &&
                            cells_[std::size_t(s)] == cell)
                            f(s);
                }
    }

    int item(int slot) const { return items_[std::size_t(slot)]; }

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

    double radius_, cell_;
    std::uint32_t mask_ = 0;
    std::vector<int> start_, items_;
    std::vector<Eigen::Vector3i> cells_;
    std::vector<Eigen::Vector3d> points_;
};

}  // namespace rend::sim
