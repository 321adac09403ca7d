#include "sim/Lattice.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

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
    return std::size_t(g.columns) * std::size_t(g.rows);
}

}  // namespace rend::sim
