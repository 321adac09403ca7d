#pragma once
// Shared fixtures and checks of the render tests: sheets the tests own (a hand-made square
// grid, or a copy of the simulator's lattice), grid meshes, pixel helpers and the image
// regression check against tests/data/<name>.png.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "render/Image.h"
#include "render/Mesh.h"
#include "sim/FrameView.h"
#include "sim/Membrane.h"

namespace rend::test {

// ---- sheets --------------------------------------------------------------------------------

/// One frame's arrays, owned by the test so that it can move particles and break bonds freely
/// without touching the solver; view() hands them to render/ as a FrameView.
struct Sheet {
    std::vector<Eigen::Vector3d> positions, velocities, rest;
    std::vector<std::array<int, 3>> triangles;
    std::vector<int> offsets, partners;
    std::vector<double> restLength;
    std::vector<std::uint8_t> alive;
    std::vector<std::uint8_t> kept;  ///< per triangle; empty: all kept

    Sheet() = default;

    /// A copy of the arrays of `v` (its theta and damage are left out).
    explicit Sheet(const sim::FrameView& v)
        : positions(v.positions.begin(), v.positions.end()),
          velocities(v.velocities.begin(), v.velocities.end()),
          rest(v.restPositions.begin(), v.restPositions.end()),
          triangles(v.restTriangles.begin(), v.restTriangles.end()),
          offsets(v.bondOffsets.begin(), v.bondOffsets.end()),
          partners(v.bondPartners.begin(), v.bondPartners.end()),
          restLength(v.bondRestLength.begin(), v.bondRestLength.end()),
          alive(v.bondAlive.begin(), v.bondAlive.end()),
          kept(v.keptTriangles.begin(), v.keptTriangles.end()) {}

    int size() const { return int(positions.size()); }

    /// Frame 1 over this sheet's arrays; valid while the sheet lives and keeps its sizes.
    sim::FrameView view() const {
        return {.frame = 1,
                .positions = positions,
                .velocities = velocities,
                .restPositions = rest,
                .theta = {},
                .damage = {},
                .restTriangles = triangles,
                .bondOffsets = offsets,
                .bondPartners = partners,
                .bondRestLength = restLength,
                .bondAlive = alive,
                .keptTriangles = kept,
                .triangleAlive = {},
                .colliders = {},
                .colliderPoses = {}};
    }

    /// Breaks the bond a-b from both ends, and drops the triangles along it as the
    /// DamageState does. Throws std::out_of_range when a and b are not bonded, so a test cannot
    /// silently break nothing.
    void breakBond(int a, int b) {
        const sim::FrameView v = view();
        alive.at(v.findBond(a, b)) = 0;
        alive.at(v.findBond(b, a)) = 0;
        kept.resize(triangles.size(), 1);
        for (std::size_t t = 0; t < triangles.size(); ++t)
            if (std::count(triangles[t].begin(), triangles[t].end(), a) &&
                std::count(triangles[t].begin(), triangles[t].end(), b))
                kept[t] = 0;
    }

    /// The particle nearest the rest point (x, y).
    int nearest(double x, double y) const {
        const auto distance = [&](int i) {
            return (rest[i].head<2>() - Eigen::Vector2d(x, y)).norm();
        };
        int best = 0;
        for (int i = 1; i < size(); ++i)
            if (distance(i) < distance(best)) best = i;
        return best;
    }
};

/// The two counter-clockwise triangles of every cell of an nx x ny vertex grid numbered row
/// by row (vertex j * nx + i), cells in the same order.
template <class Index = int>
std::vector<std::array<Index, 3>> gridTriangles(int nx, int ny) {
    const auto id = [nx](int i, int j) { return Index(j * nx + i); };
    std::vector<std::array<Index, 3>> triangles;
    for (int j = 0; j + 1 < ny; ++j) {
        for (int i = 0; i + 1 < nx; ++i) {
            triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    }
    return triangles;
}

/// z of a deformed sheet as a function of the rest point (x, y).
using HeightField = std::function<double(double x, double y)>;

/// A square particle grid in the z = 0 plane at rest, centred on the origin, with every cell
/// split into two counter-clockwise triangles and bonds to all 8 neighbours (so every triangle
/// edge, diagonals included, is a bond); the particles are lifted to z = height(x, y) when a
/// height field is given. Built here rather than by the simulator's lattice generator so tests
/// pin down render/ alone.
struct GridSheet : Sheet {
    int nx;
    int ny;
    double dx;

    GridSheet(int nx_, int ny_, double dx_, const HeightField& height = nullptr)
        : nx(nx_), ny(ny_), dx(dx_) {
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i)
                rest.emplace_back((i - 0.5 * (nx - 1)) * dx, (j - 0.5 * (ny - 1)) * dx, 0.0);
        positions = rest;
        if (height)
            for (auto& p : positions) p.z() = height(p.x(), p.y());
        velocities.assign(rest.size(), Eigen::Vector3d::Zero());
        triangles = gridTriangles(nx, ny);
        makeBonds();
    }

    int id(int i, int j) const { return j * nx + i; }

private:
    void makeBonds() {
        offsets.push_back(0);
        for (int j = 0; j < ny; ++j) {
            for (int i = 0; i < nx; ++i) {
                addNeighbours(i, j);
                offsets.push_back(static_cast<int>(partners.size()));
            }
        }
        alive.assign(partners.size(), 1);
    }

    void addNeighbours(int i, int j) {
        for (int dj = -1; dj <= 1; ++dj) {
            for (int di = -1; di <= 1; ++di) {
                const int ni = i + di;
                const int nj = j + dj;
                if ((di == 0 && dj == 0) || ni < 0 || nj < 0 || ni >= nx || nj >= ny) continue;
                partners.push_back(id(ni, nj));
                restLength.push_back((rest[id(ni, nj)] - rest[id(i, j)]).norm());
            }
        }
    }
};

/// The simulator's default (hexagonal) sheet of size sizeX x sizeY and spacing dx at rest,
/// from its public API.
inline Sheet membraneSheet(double sizeX, double sizeY, double dx) {
    sim::MembraneParams params;
    params.sheet.size = {sizeX, sizeY};
    params.sheet.dx = dx;
    const sim::Membrane membrane(params);
    return Sheet(membrane.view(1));
}

// ---- grid meshes ---------------------------------------------------------------------------

struct GridVertex {
    Eigen::Vector3f position;
    Eigen::Vector3f normal;
    Eigen::Vector3f color;
};

/// A mesh over an nx x ny vertex grid triangulated as gridTriangles; vertexAt(i, j) gives the
/// GridVertex of column i, row j.
template <class VertexAt>
render::Mesh gridMesh(int nx, int ny, VertexAt vertexAt) {
    render::Mesh mesh;
    for (int j = 0; j < ny; ++j) {
        for (int i = 0; i < nx; ++i) {
            const GridVertex vertex = vertexAt(i, j);
            mesh.positions.push_back(vertex.position);
            mesh.normals.push_back(vertex.normal);
            mesh.colors.push_back(vertex.color);
        }
    }
    mesh.triangles = gridTriangles<std::uint32_t>(nx, ny);
    return mesh;
}

// ---- pixels ----------------------------------------------------------------------------------

inline const std::uint8_t* pixel(const render::Image& image, int x, int y) {
    return &image.rgb[(std::size_t(y) * image.width + x) * 3];
}

/// Largest channel difference of two RGB pixels.
inline int pixelDistance(const std::uint8_t* a, const std::uint8_t* b) {
    int d = 0;
    for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(a[c]) - int(b[c])));
    return d;
}

/// Pixels of `image` more than `tolerance` away from `color`.
inline int pixelsUnlike(const render::Image& image, const std::uint8_t* color, int tolerance) {
    int count = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            count += pixelDistance(pixel(image, x, y), color) > tolerance;
    return count;
}

/// Pixels more than `tolerance` apart between two images of the same size.
inline int pixelsDiffering(const render::Image& a, const render::Image& b, int tolerance) {
    int count = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            count += pixelDistance(pixel(a, x, y), pixel(b, x, y)) > tolerance;
    return count;
}

// ---- image regression ------------------------------------------------------------------------

/// Where failing comparisons and other test output go: <gtest temp dir>/rend_render_tests.
inline std::filesystem::path scratchDir() {
    const std::filesystem::path dir =
        std::filesystem::path(::testing::TempDir()) / "rend_render_tests";
    std::filesystem::create_directories(dir);
    return dir;
}

/// Compares `actual` with tests/data/<name>.png: fails when more than `failingFraction` of the
/// pixels differ by more than `tolerance` (of 255) in some channel, and then writes
/// <name>_actual.png and <name>_diff.png to scratchDir(). With REND_REGENERATE_REFERENCES=1
/// in the environment it writes the reference instead.
inline void expectMatchesReference(const render::Image& actual, const std::string& name,
                                   int tolerance = 8, double failingFraction = 0.01) {
    namespace fs = std::filesystem;
    const fs::path reference = fs::path(REND_SOURCE_DIR) / "tests/data" / (name + ".png");
    const char* regenerate = std::getenv("REND_REGENERATE_REFERENCES");
    if (regenerate && std::string(regenerate) == "1") {
        render::writePngAtomic(actual, reference);
        std::cout << "[ regenerated ] " << reference << "\n";
        return;
    }
    ASSERT_TRUE(fs::exists(reference))
        << reference << " is missing; run with REND_REGENERATE_REFERENCES=1 to create it";
    const auto diff = render::compareImages(render::readPng(reference), actual, tolerance);
    if (diff.failingFraction > failingFraction) {
        const fs::path actualPath = scratchDir() / (name + "_actual.png");
        const fs::path diffPath = scratchDir() / (name + "_diff.png");
        render::writePngAtomic(actual, actualPath);
        render::writePngAtomic(diff.diff, diffPath);
        ADD_FAILURE() << "rendered image differs from " << reference << ": "
                      << diff.failingFraction * 100 << "% of pixels off by more than " << tolerance
                      << " (max " << diff.maxDifference << ")\n  actual: " << actualPath
                      << "\n  diff:   " << diffPath;
    }
}

}  // namespace rend::test
