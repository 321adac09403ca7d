#include "sim/Lattice.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <unordered_map>
#include <utility>

#include "sim/Parallel.h"
#include "sim/Random.h"

namespace rend::sim {
namespace {

struct Grid {
    int columns = 0;
    int rows = 0;
    double rowSpacing = 0.0;
    Eigen::Vector2d origin;  ///< position of column 0, row 0
    bool hexagonal = false;
};

Eigen::Vector2d halfExtent(const SheetParams& sheet) {
    if (sheet.outline == Outline::Disc) return {sheet.radius, sheet.radius};
    return 0.5 * sheet.size;
}

Grid makeGrid(const SheetParams& sheet) {
    Grid g;
    g.hexagonal = sheet.lattice == LatticeKind::Hexagonal;
    g.rowSpacing = g.hexagonal ? sheet.dx * std::sqrt(3.0) / 2.0 : sheet.dx;
    const Eigen::Vector2d half = halfExtent(sheet);
    // A relative tolerance keeps 2.0 / 0.02 from rounding down to 99 columns.
    g.columns = int(std::floor(2.0 * half.x() / sheet.dx + 1e-9)) + 1;
    g.rows = int(std::floor(2.0 * half.y() / g.rowSpacing + 1e-9)) + 1;
    g.origin = {sheet.center.x() - 0.5 * (g.columns - 1) * sheet.dx,
                sheet.center.y() - 0.5 * (g.rows - 1) * g.rowSpacing};
    return g;
}

Eigen::Vector2d gridPoint(const Grid& g, double dx, int column, int row) {
    const double shift = (g.hexagonal && (row % 2 == 1)) ? 0.5 * dx : 0.0;
    return {g.origin.x() + column * dx + shift, g.origin.y() + row * g.rowSpacing};
}

bool insideOutline(const SheetParams& sheet, const Eigen::Vector2d& p) {
    const double tol = 1e-9 * sheet.dx;
    const Eigen::Vector2d d = p - sheet.center.head<2>();
    if (sheet.outline == Outline::Disc) return d.norm() <= sheet.radius + tol;
    return std::abs(d.x()) <= 0.5 * sheet.size.x() + tol &&
           std::abs(d.y()) <= 0.5 * sheet.size.y() + tol;
}

void addTriangle(Lattice& lattice, int a, int b, int c) {
    if (a < 0 || b < 0 || c < 0) return;
    const auto& p = lattice.positions;
    const double cross = (p[b] - p[a]).head<2>().x() * (p[c] - p[a]).head<2>().y() -
                         (p[b] - p[a]).head<2>().y() * (p[c] - p[a]).head<2>().x();
    if (cross > 0)
        lattice.triangles.push_back({a, b, c});
    else
        lattice.triangles.push_back({a, c, b});
}

// Two triangles per cell between rows `row` and `row + 1`; `at(column, row)` is -1 outside.
template <class At>
void triangulateCell(Lattice& lattice, const Grid& g, int column, int row, At at) {
    const int a = at(column, row), b = at(column + 1, row);
    const int c = at(column, row + 1), d = at(column + 1, row + 1);
    if (!g.hexagonal) {
        addTriangle(lattice, a, b, d);
        addTriangle(lattice, a, d, c);
    } else if (row % 2 == 0) {  // the row above is shifted right by dx/2
        addTriangle(lattice, a, b, c);
        addTriangle(lattice, b, d, c);
    } else {  // this row is shifted right: the row above is not
        addTriangle(lattice, a, b, d);
        addTriangle(lattice, a, d, c);
    }
}

}  // namespace

Lattice generateLattice(const SheetParams& sheet) {
    if (sheet.outline == Outline::Sphere) return generateSphere(sheet);
    const Grid g = makeGrid(sheet);
    Lattice lattice;
    lattice.particleArea = sheet.dx * g.rowSpacing;
    std::vector<int> index(std::size_t(g.columns) * g.rows, -1);
    for (int row = 0; row < g.rows; ++row) {
        for (int column = 0; column < g.columns; ++column) {
            const Eigen::Vector2d p = gridPoint(g, sheet.dx, column, row);
            if (!insideOutline(sheet, p)) continue;
            index[std::size_t(row) * g.columns + column] = int(lattice.positions.size());
            lattice.positions.emplace_back(p.x(), p.y(), sheet.center.z());
        }
    }
    auto at = [&](int column, int row) {
        if (column < 0 || column >= g.columns || row < 0 || row >= g.rows) return -1;
        return index[std::size_t(row) * g.columns + column];
    };
    for (int row = 0; row + 1 < g.rows; ++row)
        for (int column = 0; column < g.columns; ++column)
            triangulateCell(lattice, g, column, row, at);
    return lattice;
}

GhostBand ghostBand(const SheetParams& sheet) {
    GhostBand band;
    if (sheet.outline == Outline::Sphere) return band;
    const Grid g = makeGrid(sheet);
    constexpr int kPad = 2;  // even, so a hexagonal grid's rows keep their shifts
    Grid wide = g;
    wide.columns += 2 * kPad;
    wide.rows += 2 * kPad;
    wide.origin -= Eigen::Vector2d(kPad * sheet.dx, kPad * g.rowSpacing);
    const auto cell = [&](int column, int row) { return std::size_t(row) * wide.columns + column; };
    std::vector<int> particle(std::size_t(wide.columns) * wide.rows, -1);
    int count = 0;  // generateLattice's numbering: row by row, inside the outline
    for (int row = 0; row < g.rows; ++row)
        for (int column = 0; column < g.columns; ++column)
            if (insideOutline(sheet, gridPoint(g, sheet.dx, column, row)))
                particle[cell(column + kPad, row + kPad)] = count++;
    Lattice all;  // every grid point of the wide grid, numbered by cell
    for (int row = 0; row < wide.rows; ++row)
        for (int column = 0; column < wide.columns; ++column) {
            const Eigen::Vector2d p = gridPoint(wide, sheet.dx, column, row);
            all.positions.emplace_back(p.x(), p.y(), sheet.center.z());
        }
    for (int row = 0; row + 1 < wide.rows; ++row)
        for (int column = 0; column < wide.columns; ++column)
            triangulateCell(all, wide, column, row,
                            [&](int c, int r) { return c < wide.columns ? int(cell(c, r)) : -1; });
    std::vector<int> ghost(particle.size(), -1);
    for (const auto& t : all.triangles) {
        int particles = 0;
        for (int c : t) particles += particle[c] >= 0;
        if (particles == 0 || particles == 3) continue;
        std::array<int, 3> corners;
        for (int k = 0; k < 3; ++k) {
            const int c = t[k];
            if (particle[c] >= 0) {
                corners[k] = particle[c];
                continue;
            }
            if (ghost[c] < 0) {
                ghost[c] = int(band.sites.size());
                band.sites.push_back(all.positions[c]);
            }
            corners[k] = count + ghost[c];
        }
        band.triangles.push_back(corners);
    }
    return band;
}

double outlineDistance(const SheetParams& sheet, const Eigen::Vector3d& p) {
    const Eigen::Vector2d d = p.head<2>() - sheet.center.head<2>();
    switch (sheet.outline) {
        case Outline::Disc:
            return d.norm() - sheet.radius;
        case Outline::Rectangle: {
            const Eigen::Vector2d q = d.cwiseAbs() - 0.5 * sheet.size;
            return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
        }
        case Outline::Sphere:
            break;
    }
    return -std::numeric_limits<double>::infinity();
}

namespace {

// The icosahedron's edge is 1.0515 R; each subdivision halves it.
int sphereSubdivisions(const SheetParams& sheet) {
    const double edge = 4.0 / std::sqrt(10.0 + 2.0 * std::sqrt(5.0)) * sheet.radius;
    return std::max(0, int(std::ceil(std::log2(edge / sheet.dx) - 1e-9)));
}

}  // namespace

Lattice generateSphere(const SheetParams& sheet) {
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<Eigen::Vector3d> p = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                      {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                      {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    std::vector<std::array<int, 3>> faces = {
        {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
        {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (auto& v : p) v.normalize();
    for (int level = sphereSubdivisions(sheet); level > 0; --level) {
        std::map<std::pair<int, int>, int> middle;
        auto midpoint = [&](int a, int b) {
            const auto [it, added] = middle.try_emplace(std::minmax(a, b), int(p.size()));
            if (added) p.push_back((p[a] + p[b]).normalized());
            return it->second;
        };
        std::vector<std::array<int, 3>> finer;
        finer.reserve(4 * faces.size());
        for (const auto& [a, b, c] : faces) {
            const int ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
            finer.insert(finer.end(), {{a, ab, ca}, {b, bc, ab}, {c, ca, bc}, {ab, bc, ca}});
        }
        faces = std::move(finer);
    }
    Lattice lattice;
    for (const auto& v : p) lattice.positions.push_back(sheet.center + sheet.radius * v);
    lattice.triangles = faces;  // counter-clockwise seen from outside
    lattice.areas.assign(p.size(), 0.0);
    double total = 0.0;
    for (const auto& [a, b, c] : faces) {
        const auto& x = lattice.positions;
        const double area = 0.5 * (x[b] - x[a]).cross(x[c] - x[a]).norm();
        for (int v : {a, b, c}) lattice.areas[v] += area / 3.0;
        total += area;
    }
    lattice.particleArea = total / double(p.size());
    return lattice;
}

std::size_t estimateParticleCount(const SheetParams& sheet) {
    if (sheet.outline == Outline::Sphere)
        return 10 * (std::size_t(1) << (2 * sphereSubdivisions(sheet))) + 2;
    const Grid g = makeGrid(sheet);
    if (sheet.outline == Outline::Rectangle) return std::size_t(g.columns) * std::size_t(g.rows);
    std::size_t count = 0;
    for (int row = 0; row < g.rows; ++row)
        for (int column = 0; column < g.columns; ++column)
            count += insideOutline(sheet, gridPoint(g, sheet.dx, column, row)) ? 1 : 0;
    return count;
}

namespace {

/// `value` to three significant digits, rounded down or up, so a chosen spacing reads like one
/// a person would type (0.00429, not 0.0042946...).
double threeDigits(double value, bool up) {
    const int exponent = int(std::floor(std::log10(value))) - 2;
    const double scale = std::pow(10.0, std::abs(exponent));
    const double scaled = exponent < 0 ? value * scale : value / scale;
    const double digits = up ? std::ceil(scaled - 1e-9) : std::floor(scaled + 1e-9);
    return exponent < 0 ? digits / scale : digits * scale;
}

}  // namespace

double spacingForParticles(SheetParams sheet, std::size_t target) {
    if (sheet.outline == Outline::Sphere) {
        // 10 4^n + 2 vertices after n subdivisions; an edge a hair longer still gives n.
        int n = 0;
        while (10 * (std::size_t(1) << (2 * n)) + 2 < target) ++n;
        const double edge = 4.0 / std::sqrt(10.0 + 2.0 * std::sqrt(5.0)) * sheet.radius;
        return threeDigits(edge / double(std::size_t(1) << n), true);
    }
    // Lattice points per unit area: 1 / dx^2 (square) or 2 / (sqrt(3) dx^2) (hexagonal).
    const double area = sheet.outline == Outline::Disc
                            ? std::numbers::pi * sheet.radius * sheet.radius
                            : sheet.size.x() * sheet.size.y();
    const double perCell = sheet.lattice == LatticeKind::Square ? 1.0 : 2.0 / std::sqrt(3.0);
    sheet.dx = threeDigits(std::sqrt(area * perCell / double(target)), false);
    while (estimateParticleCount(sheet) < target) sheet.dx = threeDigits(sheet.dx * 0.999, false);
    return sheet.dx;
}

namespace {

double seedSpacingOf(const SheetParams& sheet) {
    return sheet.seedSpacing > 0.0 ? sheet.seedSpacing : sheet.dx;
}

/// Finds, for a point in rest coordinates, the lattice triangle it lies in and its barycentric
/// weights; triangles are bucketed on a grid of cells one spacing wide.
class TriangleLocator {
public:
    TriangleLocator(const Lattice& lattice, double cell) : lattice_(lattice), cell_(cell) {
        // Each triangle in the cells its bounding box covers...
        std::unordered_map<std::int64_t, std::vector<int>> buckets;
        long lowX = std::numeric_limits<long>::max(), lowY = lowX, highX = -lowX, highY = -lowX;
        for (int t = 0; t < int(lattice.triangles.size()); ++t) {
            Eigen::Vector2d lo = point(lattice.triangles[t][0]), hi = lo;
            for (int v : lattice.triangles[t]) {
                lo = lo.cwiseMin(point(v));
                hi = hi.cwiseMax(point(v));
            }
            lowX = std::min(lowX, cellOf(lo.x())), highX = std::max(highX, cellOf(hi.x()));
            lowY = std::min(lowY, cellOf(lo.y())), highY = std::max(highY, cellOf(hi.y()));
            for (long cy = cellOf(lo.y()); cy <= cellOf(hi.y()); ++cy)
                for (long cx = cellOf(lo.x()); cx <= cellOf(hi.x()); ++cx)
                    buckets[key(cx, cy)].push_back(t);
        }
        if (buckets.empty()) return;
        // ... and, per cell of a dense grid one cell wider, the triangles of the nine cells
        // around it in the order interpolate() looks at them, each once (a triangle covers up to
        // four cells): a search of the nine cells' buckets and each of their triangles' weights
        // was the set-up's largest item after the bonds.
        firstX_ = lowX - 1, firstY_ = lowY - 1;
        width_ = highX - lowX + 3, height_ = highY - lowY + 3;
        near_.first.assign(std::size_t(width_ * height_) + 1, 0);
        std::vector<int> seen(lattice.triangles.size(), -1);
        for (long gy = 0; gy < height_; ++gy)
            for (long gx = 0; gx < width_; ++gx) {
                const long at = gy * width_ + gx;
                for (long dy = -1; dy <= 1; ++dy)
                    for (long dx = -1; dx <= 1; ++dx) {
                        const auto it = buckets.find(key(firstX_ + gx + dx, firstY_ + gy + dy));
                        if (it == buckets.end()) continue;
                        for (const int t : it->second)
                            if (seen[t] != at) seen[t] = int(at), near_.triangles.push_back(t);
                    }
                near_.first[at + 1] = int(near_.triangles.size());
            }
        // Each triangle's bounding box a millionth of a cell wider: a point outside it lies
        // outside the triangle by a millionth of its size at least, far above the weights'
        // rounding, so its smallest weight is negative.
        const double margin = 1e-6 * cell;
        boxes_.resize(lattice.triangles.size());
        for (int t = 0; t < int(lattice.triangles.size()); ++t) {
            Eigen::Vector2d lo = point(lattice.triangles[t][0]), hi = lo;
            for (int v : lattice.triangles[t]) {
                lo = lo.cwiseMin(point(v));
                hi = hi.cwiseMax(point(v));
            }
            boxes_[t] = {lo.x() - margin, lo.y() - margin, hi.x() + margin, hi.y() + margin};
        }
    }

    /// Linear interpolation of per-vertex `values` at p. Outside every triangle (the lattice's
    /// ragged rim) the least-outside nearby triangle's clamped weights extend it.
    double interpolate(const Eigen::Vector2d& p, const std::vector<double>& values) const {
        double bestInside = -std::numeric_limits<double>::infinity();
        Eigen::Vector3d bestWeights(1, 0, 0);
        int best = -1;
        const long gx = cellOf(p.x()) - firstX_, gy = cellOf(p.y()) - firstY_;
        if (gx < 0 || gy < 0 || gx >= width_ || gy >= height_) return 0.0;
        const long at = gy * width_ + gx;
        // The first of the largest smallest weight: a triangle seen again in a later cell cannot
        // pass itself. First among the triangles whose box holds p: where one holds p (weights
        // at least 0), no other can reach its smallest weight, and the answer is the same.
        for (const bool boxed : {true, false}) {
            for (int k = near_.first[at]; k < near_.first[at + 1]; ++k) {
                const int t = near_.triangles[k];
                if (boxed && !boxes_[t].holds(p)) continue;
                const Eigen::Vector3d w = weights(t, p);
                if (w.minCoeff() > bestInside) {
                    bestInside = w.minCoeff();
                    bestWeights = w;
                    best = t;
                }
            }
            if (bestInside >= 0.0 || !boxed) break;
            bestInside = -std::numeric_limits<double>::infinity(), best = -1;  // the rim
        }
        if (best < 0) return 0.0;
        const Eigen::Vector3d w = bestWeights.cwiseMax(0.0) / bestWeights.cwiseMax(0.0).sum();
        const auto& [a, b, c] = lattice_.triangles[best];
        return w[0] * values[a] + w[1] * values[b] + w[2] * values[c];
    }

private:
    Eigen::Vector2d point(int v) const { return lattice_.positions[v].head<2>(); }
    long cellOf(double coordinate) const { return long(std::floor(coordinate / cell_)); }
    static std::int64_t key(long cx, long cy) {
        return (std::int64_t(cx) << 32) ^ (cy & 0xffffffff);
    }

    Eigen::Vector3d weights(int t, const Eigen::Vector2d& p) const {
        const auto& [a, b, c] = lattice_.triangles[t];
        const Eigen::Vector2d e1 = point(b) - point(a), e2 = point(c) - point(a), d = p - point(a);
        const double det = e1.x() * e2.y() - e1.y() * e2.x();
        const double u = (d.x() * e2.y() - d.y() * e2.x()) / det;
        const double v = (e1.x() * d.y() - e1.y() * d.x()) / det;
        return {1.0 - u - v, u, v};
    }

    const Lattice& lattice_;
    double cell_;
    long firstX_ = 0, firstY_ = 0, width_ = 0, height_ = 0;  ///< the grid of cells
    struct Box {
        double loX, loY, hiX, hiY;
        bool holds(const Eigen::Vector2d& p) const {
            return p.x() >= loX && p.x() <= hiX && p.y() >= loY && p.y() <= hiY;
        }
    };
    std::vector<Box> boxes_;  ///< per triangle
    struct {
        std::vector<int> first{0}, triangles;  ///< per cell, CSR
    } near_;
};

}  // namespace

Lattice seedLattice(const SheetParams& sheet) {
    SheetParams seeds = sheet;
    seeds.dx = seedSpacingOf(sheet);
    return generateLattice(seeds);
}

std::vector<double> perturbationHeights(const SheetParams& sheet,
                                        const std::vector<Eigen::Vector3d>& positions) {
    std::vector<double> height(positions.size(), 0.0);
    if (sheet.perturbationAmplitude <= 0.0) return height;
    auto jitter = [&](std::size_t i) {
        return sheet.perturbationAmplitude *
               (2.0 * uniformFromHash(sheet.perturbationSeed, std::uint64_t(i)) - 1.0);
    };
    const double spacing = seedSpacingOf(sheet);
    // One value per particle at the seed spacing itself (and on the sphere, which has no flat
    // lattice to interpolate on).
    if (spacing == sheet.dx || sheet.outline == Outline::Sphere) {
        for (std::size_t i = 0; i < positions.size(); ++i) height[i] = jitter(i);
        return height;
    }
    const Lattice coarse = seedLattice(sheet);
    std::vector<double> values(coarse.positions.size());
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = jitter(i);
    const TriangleLocator locator(coarse, spacing);
    // Each particle's own search of the nine cells around it (0.2 s of the final foil's set-up
    // on one thread), on every thread.
    const int count = int(positions.size());
    forEachIndex(count > kParallelThreshold, 0, count,
                 [&](int i) { height[i] = locator.interpolate(positions[i].head<2>(), values); });
    return height;
}

}  // namespace rend::sim
