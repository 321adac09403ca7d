// surface = "particle_level_set" (render/LatticeSurface.h, Outline::LevelSet): the lattice
// surface with its outline drawn by seed 004's particle level set.

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <numeric>
#include <set>
#include <utility>

#include "render/LatticeSurface.h"
#include "sim/Lattice.h"
#include "sim/Membrane.h"

using namespace rend;
using render::LatticeSurface;

namespace {

sim::MembraneParams sheet(sim::Outline outline,
                          sim::LatticeKind lattice = sim::LatticeKind::Hexagonal) {
    sim::MembraneParams p;
    p.sheet.outline = outline;
    p.sheet.size = {0.2, 0.1};
    p.sheet.radius = 0.1;
    p.sheet.dx = 0.01;
    p.sheet.lattice = lattice;
    p.particleLevelSet = true;
    return p;
}

/// The mesh's area at rest (each vertex's rest point), which is the sheet's it covers.
double restArea(const render::Mesh& mesh) {
    double area = 0.0;
    for (const auto& t : mesh.triangles) {
        const Eigen::Vector3f& a = mesh.points[t[0]].rest;
        area += 0.5 * double((mesh.points[t[1]].rest - a).cross(mesh.points[t[2]].rest - a).z());
    }
    return area;
}

/// Edges used by one triangle, and whether any is used by more than two.
std::pair<std::vector<std::pair<std::uint32_t, std::uint32_t>>, bool> boundary(
    const render::Mesh& mesh) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
    for (const auto& t : mesh.triangles)
        for (int k = 0; k < 3; ++k) ++uses[std::minmax(t[k], t[(k + 1) % 3])];
    std::vector<std::pair<std::uint32_t, std::uint32_t>> once;
    bool nonManifold = false;
    for (const auto& [edge, count] : uses) {
        if (count == 1) once.push_back(edge);
        nonManifold = nonManifold || count > 2;
    }
    return {once, nonManifold};
}

std::size_t looseParts(const render::Mesh& mesh) {
    std::vector<std::uint32_t> parent(mesh.positions.size());
    std::iota(parent.begin(), parent.end(), 0u);
    const auto root = [&](std::uint32_t v) {
        while (parent[v] != v) v = parent[v] = parent[parent[v]];
        return v;
    };
    std::set<std::uint32_t> used;
    for (const auto& f : mesh.triangles) {
        used.insert(f.begin(), f.end());
        parent[root(f[0])] = root(f[1]);
        parent[root(f[1])] = root(f[2]);
    }
    std::set<std::uint32_t> roots;
    for (std::uint32_t v : used) roots.insert(root(v));
    return roots.size();
}

}  // namespace

// An intact disc and rectangle: the level-set surface covers the scene's outline, the lattice
// surface only its particles' hull; its boundary lies on the outline (corners chamfered within a
// quarter spacing), it is manifold with one boundary loop, and the particles keep their vertices.
TEST(LevelSetSurface, AnIntactSheetCoversItsOutlineExactly) {
    for (const auto& [outline, lattice] :
         {std::pair{sim::Outline::Disc, sim::LatticeKind::Hexagonal},
          std::pair{sim::Outline::Rectangle, sim::LatticeKind::Hexagonal},
          std::pair{sim::Outline::Rectangle, sim::LatticeKind::Square}}) {
        const sim::MembraneParams p = sheet(outline, lattice);
        sim::Membrane m(p);
        const sim::FrameView frame = m.view(1);
        const render::RenderSettings settings;
        const render::Mesh level =
            LatticeSurface(frame, LatticeSurface::Outline::LevelSet).build(frame, settings);
        const render::Mesh plain = LatticeSurface(frame).build(frame, settings);
        const double exact = outline == sim::Outline::Disc
                                 ? std::numbers::pi * p.sheet.radius * p.sheet.radius
                                 : p.sheet.size.x() * p.sheet.size.y();
        std::printf("rest area over the outline's: level set %.5f, lattice %.5f\n",
                    restArea(level) / exact, restArea(plain) / exact);
        // A level set chamfers a rectangle's corners: about 0.12 dx^2 each, 0.24% of this one.
        EXPECT_NEAR(restArea(level) / exact, 1.0, 3e-3);
        if (!(outline == sim::Outline::Rectangle && lattice == sim::LatticeKind::Square))
            EXPECT_LT(restArea(plain) / exact, 0.98);
        const auto [edges, nonManifold] = boundary(level);
        EXPECT_FALSE(nonManifold);
        std::set<std::uint32_t> loop;
        double worst = 0.0;
        for (const auto& [a, b] : edges) {
            loop.insert(a), loop.insert(b);
            for (std::uint32_t v : {a, b}) {
                const Eigen::Vector3d rest = level.points[v].rest.cast<double>();
                worst = std::max(worst, std::abs(sim::outlineDistance(p.sheet, rest)));
            }
        }
        EXPECT_EQ(loop.size(), edges.size());  // one closed loop: as many vertices as edges
        EXPECT_LT(worst, 0.25 * p.sheet.dx);
        EXPECT_EQ(looseParts(level), 1u);
        for (int i = 0; i < m.particleCount(); ++i)
            ASSERT_EQ(level.positions[i], m.positions()[i].cast<float>());
    }
}

// A cut right across the sheet, pulled apart: the level-set surface falls into the same two
// pieces as the lattice surface, and no band triangle bridges the gap.
TEST(LevelSetSurface, ACrackThroughTheOutlineLeavesTwoPieces) {
    sim::MembraneParams p = sheet(sim::Outline::Rectangle);
    p.notches.push_back({{{0.0025, -0.06}, {0.0025, 0.06}}});
    sim::Membrane m(p);
    for (int i = 0; i < m.particleCount(); ++i)
        if (m.restPositions()[i].x() > 0.0025) m.positions()[i].x() += 0.05;
    for (int s = 0; s < 20; ++s) m.step();  // one reinitialisation, the ghosts re-placed
    const sim::FrameView frame = m.view(1);
    const render::RenderSettings settings;
    const render::Mesh level =
        LatticeSurface(frame, LatticeSurface::Outline::LevelSet).build(frame, settings);
    EXPECT_EQ(looseParts(level), 2u);
    EXPECT_EQ(looseParts(LatticeSurface(frame).build(frame, settings)), 2u);
    for (const auto& t : level.triangles)
        for (int k = 0; k < 3; ++k)
            EXPECT_LT((level.positions[t[k]] - level.positions[t[(k + 1) % 3]]).norm(),
                      2.0 * p.sheet.dx);
}

// A sphere has no outline: no ghosts, and its level-set surface is its lattice surface.
TEST(LevelSetSurface, ASphereIsItsLatticeSurface) {
    sim::Membrane m(sheet(sim::Outline::Sphere));
    const sim::FrameView frame = m.view(1);
    EXPECT_TRUE(frame.ghostPositions.empty());
    const render::RenderSettings settings;
    const render::Mesh level =
        LatticeSurface(frame, LatticeSurface::Outline::LevelSet).build(frame, settings);
    const render::Mesh plain = LatticeSurface(frame).build(frame, settings);
    EXPECT_EQ(level.triangles, plain.triangles);
    EXPECT_EQ(level.positions, plain.positions);
}
