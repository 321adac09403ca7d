// Tests for the splat, vdb and extruded lattice surfaces and for mesh export (ply, obj, glb).

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <numbers>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "TestSupport.h"
#include "render/ColorMap.h"
#include "render/EmbreeRenderer.h"
#include "render/GlbExport.h"
#include "render/LatticeSurface.h"
#include "render/MeshExport.h"
#include "render/SheetVolume.h"
#include "render/SplatSurface.h"
#include "render/VdbSurface.h"
#include "sim/FrameView.h"
#include "sim/Membrane.h"

namespace fs = std::filesystem;
using rend::render::ColorBy;
using rend::render::LatticeSurface;
using rend::render::Mesh;
using rend::render::MeshFormat;
using rend::render::RenderSettings;
using rend::render::SplatSurface;
using rend::render::VdbSettings;
using rend::render::VdbSurface;
using rend::sim::FrameView;
using rend::test::membraneSheet;
using rend::test::Sheet;

namespace {

constexpr double kDx = 0.02;

// z = A sin(k x): a wavy sheet with a known normal everywhere.
constexpr double kWaveAmplitude = 0.02;
constexpr double kWaveNumber = 2.0 * std::numbers::pi / 0.3;

void makeWavy(Sheet& frame) {
    for (int i = 0; i < frame.size(); ++i)
        frame.positions[i].z() = kWaveAmplitude * std::sin(kWaveNumber * frame.rest[i].x());
}

Eigen::Vector3d waveNormal(double x) {
    return Eigen::Vector3d(-kWaveAmplitude * kWaveNumber * std::cos(kWaveNumber * x), 0.0, 1.0)
        .normalized();
}

double angleDegrees(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 /
           std::numbers::pi;
}

fs::path scratchDir(const std::string& name) {
    const fs::path dir = fs::path(::testing::TempDir()) / "rend_surface_tests" / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

bool anyTmpLeft(const fs::path& dir) {
    for (const auto& entry : fs::directory_iterator(dir))
        if (entry.path().string().ends_with(".tmp")) return true;
    return false;
}

// ---- mesh topology -------------------------------------------------------------------------

using Edge = std::pair<std::uint32_t, std::uint32_t>;

std::map<Edge, int> undirectedEdgeUse(const Mesh& mesh) {
    std::map<Edge, int> use;
    for (const auto& t : mesh.triangles)
        for (int e = 0; e < 3; ++e) ++use[std::minmax(t[e], t[(e + 1) % 3])];
    return use;
}

// Every edge shared by exactly two triangles, walked once in each direction: a closed,
// consistently oriented surface.
bool isClosedAndOriented(const Mesh& mesh) {
    std::map<Edge, int> directed;
    for (const auto& t : mesh.triangles)
        for (int e = 0; e < 3; ++e) ++directed[{t[e], t[(e + 1) % 3]}];
    for (const auto& [edge, count] : directed) {
        const auto reverse = directed.find({edge.second, edge.first});
        if (count != 1 || reverse == directed.end() || reverse->second != 1) return false;
    }
    return !mesh.triangles.empty();
}

int referencedVertexCount(const Mesh& mesh) {
    std::set<std::uint32_t> used;
    for (const auto& t : mesh.triangles) used.insert(t.begin(), t.end());
    return int(used.size());
}

int eulerCharacteristic(const Mesh& mesh) {
    return referencedVertexCount(mesh) - int(undirectedEdgeUse(mesh).size()) +
           int(mesh.triangles.size());
}

int componentCount(const Mesh& mesh) {
    std::vector<std::uint32_t> parent(mesh.positions.size());
    for (std::uint32_t v = 0; v < parent.size(); ++v) parent[v] = v;
    auto find = [&](std::uint32_t v) {
        while (parent[v] != v) v = parent[v] = parent[parent[v]];
        return v;
    };
    for (const auto& t : mesh.triangles) {
        parent[find(t[1])] = find(t[0]);
        parent[find(t[2])] = find(t[0]);
    }
    std::set<std::uint32_t> roots;
    for (const auto& t : mesh.triangles) roots.insert(find(t[0]));
    return int(roots.size());
}

// Merges vertices with bit-identical positions (the extruded lattice's wall vertices are exact
// copies of the face vertices).
Mesh weldByPosition(const Mesh& mesh) {
    std::map<std::tuple<float, float, float>, std::uint32_t> index;
    std::vector<std::uint32_t> remap(mesh.positions.size());
    Mesh welded;
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
        const auto& p = mesh.positions[v];
        const auto [it, inserted] =
            index.try_emplace({p.x(), p.y(), p.z()}, std::uint32_t(welded.positions.size()));
        if (inserted) welded.positions.push_back(p);
        remap[v] = it->second;
    }
    for (const auto& t : mesh.triangles)
        welded.triangles.push_back({remap[t[0]], remap[t[1]], remap[t[2]]});
    return welded;
}

void expectWellFormed(const Mesh& mesh) {
    ASSERT_EQ(mesh.positions.size(), mesh.normals.size());
    ASSERT_EQ(mesh.positions.size(), mesh.colors.size());
    for (const auto& t : mesh.triangles)
        for (auto v : t) ASSERT_LT(v, mesh.positions.size());
    for (const auto& n : mesh.normals) ASSERT_NEAR(n.norm(), 1.0f, 1e-4f);
}

}  // namespace

// ---- SplatSurface ----------------------------------------------------------------------------

TEST(SplatSurface, FlatSheetGetsOneOverlappingUpwardDiscPerParticle) {
    const Sheet frame = membraneSheet(0.3, 0.2, kDx);
    const auto splats = SplatSurface(frame.view()).build(frame.view(), RenderSettings{});
    ASSERT_EQ(int(splats.centers.size()), frame.size());
    ASSERT_EQ(splats.normals.size(), splats.centers.size());
    ASSERT_EQ(splats.colors.size(), splats.centers.size());
    ASSERT_EQ(splats.radii.size(), splats.centers.size());
    for (int i = 0; i < frame.size(); ++i) {
        // Neighbours are dx apart, so radii above dx / 2 overlap.
        EXPECT_GT(splats.radii[i], 0.5 * kDx);
        EXPECT_NEAR(splats.normals[i].norm(), 1.0f, 1e-5f);
        EXPECT_GT(splats.normals[i].z(), 0.9999f) << "particle " << i;
        EXPECT_TRUE(splats.centers[i].isApprox(frame.positions[i].cast<float>()));
    }
}

TEST(SplatSurface, RadiusCoversTheHexagonalLattice) {
    // The plane is covered when the radius reaches the triangles' circumradius dx / sqrt(3).
    const Sheet frame = membraneSheet(0.2, 0.2, kDx);
    EXPECT_GT(SplatSurface(frame.view()).radius(), kDx / std::sqrt(3.0));
    EXPECT_NEAR(rend::render::restSpacing(frame.view()), kDx, 1e-9);
}

TEST(SplatSurface, NormalsFollowAWavySheet) {
    Sheet frame = membraneSheet(0.6, 0.3, kDx);
    makeWavy(frame);
    const auto splats = SplatSurface(frame.view()).build(frame.view(), RenderSettings{});
    double worst = 0.0;
    for (int i = 0; i < frame.size(); ++i)
        worst = std::max(
            worst, angleDegrees(splats.normals[i].cast<double>(), waveNormal(frame.rest[i].x())));
    EXPECT_LT(worst, 10.0);
}

TEST(SplatSurface, NormalsStayOnTheRestUpperSideWhenTheSheetIsTurnedOver) {
    // Rotated by pi about x: the side that faced +z at rest now faces -z, and every normal
    // must say so (no per-particle flip towards +z).
    Sheet frame = membraneSheet(0.3, 0.2, kDx);
    for (auto& p : frame.positions) p = Eigen::Vector3d(p.x(), -p.y(), -p.z() + 0.1);
    const auto splats = SplatSurface(frame.view()).build(frame.view(), RenderSettings{});
    for (const auto& n : splats.normals) EXPECT_LT(n.z(), -0.9999f);
}

TEST(SplatSurface, ParticleWithoutTrianglesFallsBackToItsNeighbourPlane) {
    Sheet frame = membraneSheet(0.6, 0.3, kDx);
    makeWavy(frame);
    const SplatSurface surface(frame.view());
    // Break the outer ring of the particle's star: its triangles all go, its bonds stay.
    const int p = frame.nearest(0.04, 0.0);
    for (const auto& t : frame.triangles) {
        if (std::find(t.begin(), t.end(), p) == t.end()) continue;
        for (int e = 0; e < 3; ++e)
            if (t[e] != p && t[(e + 1) % 3] != p) frame.breakBond(t[e], t[(e + 1) % 3]);
    }
    const auto splats = surface.build(frame.view(), RenderSettings{});
    const Eigen::Vector3d expected = waveNormal(frame.rest[p].x());
    EXPECT_LT(angleDegrees(splats.normals[p].cast<double>(), expected), 10.0);
    // And the same way up when the whole sheet is turned over.
    for (auto& x : frame.positions) x = Eigen::Vector3d(x.x(), -x.y(), -x.z());
    const auto turned = surface.build(frame.view(), RenderSettings{});
    const Eigen::Vector3d turnedExpected(expected.x(), -expected.y(), -expected.z());
    EXPECT_LT(angleDegrees(turned.normals[p].cast<double>(), turnedExpected), 10.0);
}

TEST(SplatSurface, IsolatedParticlePointsUp) {
    Sheet frame = membraneSheet(0.2, 0.2, kDx);
    const SplatSurface surface(frame.view());
    const int p = frame.nearest(0.0, 0.0);
    for (int b = frame.offsets[p]; b < frame.offsets[p + 1]; ++b)
        frame.breakBond(p, frame.partners[b]);
    for (auto& x : frame.positions) x = Eigen::Vector3d(x.x(), -x.y(), -x.z());
    const auto splats = surface.build(frame.view(), RenderSettings{});
    EXPECT_TRUE(splats.normals[p].isApprox(Eigen::Vector3f::UnitZ()));
}

TEST(SplatSurface, ColoursComeFromTheColourMap) {
    Sheet frame = membraneSheet(0.2, 0.2, kDx);
    for (int i = 0; i < frame.size(); ++i) frame.velocities[i] = Eigen::Vector3d(i, 0.0, 0.0);
    RenderSettings settings;
    settings.colorBy = ColorBy::Speed;
    const auto splats = SplatSurface(frame.view()).build(frame.view(), settings);
    EXPECT_EQ(splats.colors, rend::render::particleColors(frame.view(), settings));
}

TEST(SplatSurface, RestWithoutBondsOrTrianglesIsRefused) {
    const std::vector<Eigen::Vector3d> points{{0, 0, 0}, {1, 0, 0}};
    FrameView v;
    v.positions = points;
    v.restPositions = points;
    EXPECT_THROW(SplatSurface{v}, std::invalid_argument);
}

TEST(SplatSurface, MeshHasAFanPerDiscFacingItsNormal) {
    Sheet frame = membraneSheet(0.2, 0.2, kDx);
    makeWavy(frame);
    const auto splats = SplatSurface(frame.view()).build(frame.view(), RenderSettings{});
    constexpr int kSegments = 6;
    const Mesh mesh = rend::render::splatsToMesh(splats, kSegments);
    expectWellFormed(mesh);
    ASSERT_EQ(mesh.positions.size(), splats.centers.size() * (kSegments + 1));
    ASSERT_EQ(mesh.triangles.size(), splats.centers.size() * kSegments);
    const float rim = splats.radii[0] / std::cos(std::numbers::pi_v<float> / kSegments);
    for (std::size_t d = 0; d < splats.centers.size(); ++d) {
        EXPECT_TRUE(mesh.positions[d * (kSegments + 1)].isApprox(splats.centers[d]));
        EXPECT_NEAR((mesh.positions[d * (kSegments + 1) + 1] - splats.centers[d]).norm(), rim,
                    1e-5f);
        for (int k = 0; k < kSegments; ++k) {
            const auto& t = mesh.triangles[d * kSegments + k];
            const Eigen::Vector3f n = (mesh.positions[t[1]] - mesh.positions[t[0]])
                                          .cross(mesh.positions[t[2]] - mesh.positions[t[0]]);
            EXPECT_GT(n.normalized().dot(splats.normals[d]), 0.9999f);
        }
    }
    EXPECT_THROW(rend::render::splatsToMesh(splats, 2), std::invalid_argument);
}

// ---- VdbSurface ------------------------------------------------------------------------------

namespace {

void expectOneClosedPillow(const Mesh& mesh) {
    expectWellFormed(mesh);
    EXPECT_EQ(componentCount(mesh), 1);
    EXPECT_TRUE(isClosedAndOriented(mesh));
    EXPECT_EQ(eulerCharacteristic(mesh), 2);  // a sphere: no hole through the sheet
}

}  // namespace

TEST(VdbSurface, FlatSheetIsOneClosedPillowWithoutHoles) {
    const Sheet frame = membraneSheet(0.3, 0.2, kDx);
    VdbSurface surface(frame.view(), VdbSettings{});
    EXPECT_NEAR(surface.voxelSize(), 0.5 * kDx, 1e-12);
    EXPECT_NEAR(surface.particleRadius(), 0.75 * kDx, 1e-12);
    const Mesh mesh = surface.build(frame.view(), RenderSettings{});
    EXPECT_EQ(surface.droppedParticles(), 0);
    expectOneClosedPillow(mesh);
    // Outward normals: up on the upper face, down on the lower one.
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
        const auto& p = mesh.positions[v];
        if (std::abs(p.x()) > 0.1f || std::abs(p.y()) > 0.05f) continue;  // interior only
        if (p.z() > 0.5f * kDx) {
            EXPECT_GT(mesh.normals[v].z(), 0.5f);
        } else if (p.z() < -0.5f * kDx) {
            EXPECT_LT(mesh.normals[v].z(), -0.5f);
        }
    }
}

TEST(VdbSurface, SmoothingKeepsAThinSheetIntact) {
    Sheet frame = membraneSheet(0.6, 0.3, kDx);
    makeWavy(frame);
    for (int iterations : {0, 2, 4}) {
        SCOPED_TRACE(iterations);
        VdbSettings settings;
        settings.smoothingIterations = iterations;
        VdbSurface surface(frame.view(), settings);
        expectOneClosedPillow(surface.build(frame.view(), RenderSettings{}));
        EXPECT_EQ(surface.droppedParticles(), 0);
    }
}

TEST(VdbSurface, SmoothingKeepsTheFlatPillowAboutOneAndAHalfDxThick) {
    const Sheet frame = membraneSheet(0.3, 0.2, kDx);
    for (int iterations : {0, 1, 2, 4}) {
        SCOPED_TRACE(iterations);
        VdbSettings settings;
        settings.smoothingIterations = iterations;
        const Mesh mesh = VdbSurface(frame.view(), settings).build(frame.view(), RenderSettings{});
        float top = -1.0f, bottom = 1.0f;
        for (const auto& p : mesh.positions) {
            top = std::max(top, p.z());
            bottom = std::min(bottom, p.z());
        }
        EXPECT_GT(top - bottom, 1.2 * kDx);
        EXPECT_LT(top - bottom, 1.6 * kDx);
        EXPECT_NEAR(top + bottom, 0.0f, 0.05 * kDx);
    }
}

TEST(VdbSurface, SheetWithAHoleHasEulerCharacteristicZero) {
    // Checks the hole detector above: without the particles near the centre the pillow is a
    // torus.
    const Sheet frame = membraneSheet(0.3, 0.2, kDx);
    std::vector<Eigen::Vector3d> kept;
    for (const auto& p : frame.positions)
        if (p.head<2>().norm() > 2.5 * kDx) kept.push_back(p);
    const std::vector<Eigen::Vector3d> still(kept.size(), Eigen::Vector3d::Zero());
    FrameView holed;
    holed.positions = kept;
    holed.velocities = still;
    VdbSurface surface(frame.view(), VdbSettings{});
    const Mesh mesh = surface.build(holed, RenderSettings{});
    EXPECT_EQ(componentCount(mesh), 1);
    EXPECT_TRUE(isClosedAndOriented(mesh));
    EXPECT_EQ(eulerCharacteristic(mesh), 0);
}

TEST(VdbSurface, SheetCutInTwoGivesTwoComponents) {
    Sheet frame = membraneSheet(0.3, 0.2, kDx);
    VdbSurface surface(frame.view(), VdbSettings{});
    for (int i = 0; i < frame.size(); ++i)
        if (frame.rest[i].x() > 0.0) frame.positions[i].x() += 10.0 * kDx;
    const Mesh mesh = surface.build(frame.view(), RenderSettings{});
    EXPECT_EQ(componentCount(mesh), 2);
    EXPECT_TRUE(isClosedAndOriented(mesh));
}

TEST(VdbSurface, VerticesTakeTheColourOfTheNearestParticle) {
    Sheet frame = membraneSheet(0.3, 0.2, kDx);
    for (int i = 0; i < frame.size(); ++i)
        frame.velocities[i] = Eigen::Vector3d(frame.rest[i].x() > 0.0 ? 1.0 : 0.0, 0.0, 0.0);
    RenderSettings settings;
    settings.colorBy = ColorBy::Speed;
    VdbSurface surface(frame.view(), VdbSettings{});
    const Mesh mesh = surface.build(frame.view(), settings);
    const Eigen::Vector3f slow = rend::render::colormap(0.0);
    const Eigen::Vector3f fast = rend::render::colormap(1.0);
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
        if (mesh.positions[v].x() > 2 * kDx) {
            EXPECT_TRUE(mesh.colors[v].isApprox(fast));
        } else if (mesh.positions[v].x() < -2 * kDx) {
            EXPECT_TRUE(mesh.colors[v].isApprox(slow));
        }
    }
}

namespace {

/// Two flat squares of side `side` in z = 0, `gap` apart along x, two triangles each; vertex
/// v stands for particle v (no Point ids).
Mesh twoSquares(float side, float gap) {
    Mesh mesh;
    for (const float x0 : {-gap / 2 - side, gap / 2}) {
        const auto base = std::uint32_t(mesh.positions.size());
        for (const auto& [x, y] : {std::pair{0.f, 0.f}, {side, 0.f}, {side, side}, {0.f, side}})
            mesh.positions.emplace_back(x0 + x, y - side / 2, 0.f);
        mesh.triangles.push_back({base, base + 1, base + 2});
        mesh.triangles.push_back({base, base + 2, base + 3});
    }
    return mesh;
}

std::map<std::string, std::size_t> gridIndex(const rend::render::VdbFileInfo& info) {
    std::map<std::string, std::size_t> index;
    for (std::size_t k = 0; k < info.gridNames.size(); ++k) index[info.gridNames[k]] = k;
    return index;
}

}  // namespace

// Issue 14: the exported level set is the sheet at its own thickness, not a pillow of
// particle spheres: zero at +-h/2 about the mid-surface, -h/2 on it, positive beyond.
TEST(SheetVolume, TheLevelSetHoldsTheSheetsThicknessWhereTheVoxelResolvesIt) {
    using rend::render::sampleVdb;
    const double h = 0.004, voxel = 0.001;
    const fs::path file = scratchDir("sheet_volume") / "frame_0001.vdb";
    const auto info = rend::render::writeSheetVolume(twoSquares(0.1f, 0.05f), {}, voxel, h, file);
    EXPECT_DOUBLE_EQ(info.thickness, h);
    const Eigen::Vector3d centre(-0.075, 0.0, 0.0);
    EXPECT_NEAR(sampleVdb(file, "surface", centre), -h / 2, 0.1 * voxel);
    for (const double side : {-1.0, 1.0}) {
        EXPECT_NEAR(sampleVdb(file, "surface", centre + Eigen::Vector3d(0, 0, side * h / 2)), 0.0,
                    0.1 * voxel);
        EXPECT_NEAR(sampleVdb(file, "surface", centre + Eigen::Vector3d(0, 0, side * h)), h / 2,
                    0.1 * voxel);
    }
    EXPECT_NEAR(sampleVdb(file, "density", centre), 1.0f, 1e-4f) << "Blender's fog: 1 inside";
    EXPECT_EQ(sampleVdb(file, "density", centre + Eigen::Vector3d(0, 0, h)), 0.0f);
    // The gap between the two pieces stays open: outside, with no fog.
    EXPECT_GT(sampleVdb(file, "surface", Eigen::Vector3d::Zero()), 0.0f);
    EXPECT_EQ(sampleVdb(file, "density", Eigen::Vector3d::Zero()), 0.0f);
    const auto read = rend::render::inspectVdb(file);
    const auto index = gridIndex(read);
    ASSERT_EQ(read.gridCount, 2u);
    ASSERT_EQ(index.count("surface") + index.count("density"), 2u);
    EXPECT_EQ(read.activeVoxels[index.at("surface")], info.activeVoxels);
    EXPECT_NEAR(read.firstGridVoxelSize, voxel, 1e-12);
    EXPECT_FALSE(anyTmpLeft(file.parent_path()));
}

// A frame with no triangle left (every bond broken) still writes whole files.
TEST(SheetVolume, AnEmptySurfaceWritesEmptyGridsAndAnEmptyGlb) {
    const fs::path dir = scratchDir("sheet_volume_empty");
    Mesh points;
    points.positions = {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1, 0, 0)};
    const auto info = rend::render::writeSheetVolume(points, {}, 0.01, 0.001, dir / "e.vdb");
    EXPECT_EQ(info.activeVoxels, 0u);
    EXPECT_EQ(rend::render::inspectVdb(dir / "e.vdb").gridCount, 2u);
    const std::string glb = rend::render::glbBytes(points);
    std::uint32_t header[5];
    ASSERT_GE(glb.size(), sizeof header);
    std::memcpy(header, glb.data(), sizeof header);
    EXPECT_EQ(header[0], 0x46546C67u) << "glTF";
    EXPECT_EQ(header[2], glb.size());
    EXPECT_EQ(header[3] + 20, glb.size()) << "the JSON chunk alone: no buffer without a mesh";
    EXPECT_EQ(glb.find("\"meshes\""), std::string::npos);
}

// A level set samples at voxel centres: a sheet thinner than two voxels would fall into holes,
// so it is written two voxels thick, and says so.
TEST(SheetVolume, ASheetThinnerThanTwoVoxelsIsWrittenTwoVoxelsThick) {
    const double h = 0.001, voxel = 0.005;
    EXPECT_DOUBLE_EQ(rend::render::sheetVolumeThickness(h, voxel), 2 * voxel);
    EXPECT_DOUBLE_EQ(rend::render::sheetVolumeThickness(h, h / 2), h);
    const fs::path file = scratchDir("sheet_volume_thin") / "frame_0001.vdb";
    const auto info = rend::render::writeSheetVolume(twoSquares(0.2f, 0.1f), {}, voxel, h, file);
    EXPECT_DOUBLE_EQ(info.thickness, 2 * voxel);
    const Eigen::Vector3d centre(-0.15, 0.0, 0.0);
    EXPECT_NEAR(rend::render::sampleVdb(file, "surface", centre), -voxel, 0.1 * voxel);
    EXPECT_THROW(rend::render::writeSheetVolume(twoSquares(0.2f, 0.1f), {}, 0.0, h, file),
                 std::invalid_argument);
}

// Issue 14: theta as a grid beside the shape, each voxel holding its closest triangle's
// particles' mean, through the mesh's particle ids.
TEST(SheetVolume, ThetaIsWrittenAsAGridOfTheClosestTrianglesParticles) {
    Mesh mesh = twoSquares(0.1f, 0.05f);
    mesh.points.resize(mesh.positions.size());
    for (std::size_t v = 0; v < mesh.points.size(); ++v)
        mesh.points[v].id = std::int32_t(mesh.points.size() - 1 - v);  // reversed
    const std::vector<double> theta{2, 2, 2, 2, 5, 5, 5, 5};  // particles 4-7: the left square
    const fs::path file = scratchDir("sheet_volume_theta") / "frame_0001.vdb";
    rend::render::writeSheetVolume(mesh, theta, 0.002, 0.004, file);
    const auto info = rend::render::inspectVdb(file);
    const auto index = gridIndex(info);
    ASSERT_EQ(index.count("theta"), 1u);
    EXPECT_NEAR(info.range[index.at("theta")][0], 2.0f, 1e-6f);
    EXPECT_NEAR(info.range[index.at("theta")][1], 5.0f, 1e-6f);
    EXPECT_NEAR(rend::render::sampleVdb(file, "theta", {-0.075, 0, 0}), 5.0f, 1e-5f);
    EXPECT_NEAR(rend::render::sampleVdb(file, "theta", {0.075, 0, 0}), 2.0f, 1e-5f);
}

TEST(VdbSurface, RadiusBelowOneAndAHalfVoxelsIsRefused) {
    const Sheet frame = membraneSheet(0.2, 0.2, kDx);
    VdbSettings settings;
    settings.voxelSize = 0.01;
    settings.particleRadius = 0.0149;
    EXPECT_THROW(VdbSurface(frame.view(), settings), std::invalid_argument);
    settings.voxelSize = 0.0;  // dx / 2 = 0.01 again, from the rest spacing
    EXPECT_THROW(VdbSurface(frame.view(), settings), std::invalid_argument);
    // Exactly 1.5 voxels is the smallest OpenVDB keeps: accepted, and nothing dropped.
    settings.particleRadius = 0.015;
    VdbSurface edge(frame.view(), settings);
    edge.build(frame.view(), RenderSettings{});
    EXPECT_EQ(edge.droppedParticles(), 0);
}

// ---- LatticeSurface thickness ----------------------------------------------------------------

TEST(LatticeThickness, ZeroThicknessIsTheSheet) {
    const Sheet frame = membraneSheet(0.2, 0.2, kDx);
    const Mesh mesh = LatticeSurface(frame.view()).build(frame.view(), RenderSettings{});
    EXPECT_EQ(int(mesh.positions.size()), frame.size());
    EXPECT_EQ(mesh.triangles.size(), frame.triangles.size());
}

TEST(LatticeThickness, ExtrudedIntactSheetIsAClosedSlab) {
    const Sheet frame = membraneSheet(0.3, 0.2, kDx);
    RenderSettings settings;
    settings.thickness = 0.004;
    const Mesh mesh = LatticeSurface(frame.view()).build(frame.view(), settings);
    expectWellFormed(mesh);
    // Top face keeps the particle indices, offset by half the thickness.
    for (int i = 0; i < frame.size(); ++i) EXPECT_NEAR(mesh.positions[i].z(), 0.002f, 1e-7f);
    const Mesh welded = weldByPosition(mesh);
    EXPECT_TRUE(isClosedAndOriented(welded));
    EXPECT_EQ(eulerCharacteristic(welded), 2);
    EXPECT_EQ(componentCount(welded), 1);
}

TEST(LatticeThickness, CrackGetsWallsOnBothLips) {
    Sheet frame = membraneSheet(0.3, 0.2, kDx);
    const LatticeSurface surface(frame.view());
    // Cut every bond crossing x = 0.005 and pull the right half 4 mm away: two closed slabs.
    for (int i = 0; i < frame.size(); ++i)
        for (int b = frame.offsets[i]; b < frame.offsets[i + 1]; ++b)
            if ((frame.rest[i].x() < 0.005) != (frame.rest[frame.partners[b]].x() < 0.005))
                frame.breakBond(i, frame.partners[b]);
    for (int i = 0; i < frame.size(); ++i)
        if (frame.rest[i].x() > 0.005) frame.positions[i].x() += 0.004;
    RenderSettings settings;
    settings.thickness = 0.004;
    const Mesh welded = weldByPosition(surface.build(frame.view(), settings));
    EXPECT_TRUE(isClosedAndOriented(welded));
    EXPECT_EQ(componentCount(welded), 2);
}

// ---- LatticeSurface cuts and outline -------------------------------------------------------

namespace {

double crossZ(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
    const Eigen::Vector2d u = b - a, v = c - a;
    return u.x() * v.y() - u.y() * v.x();
}

// Breaks every bond whose rest segment crosses the segment p -> q, as a scene's notch does.
void cutAlong(Sheet& frame, const Eigen::Vector2d& p, const Eigen::Vector2d& q) {
    for (int i = 0; i < frame.size(); ++i) {
        for (int b = frame.offsets[i]; b < frame.offsets[i + 1]; ++b) {
            const int j = frame.partners[b];
            const Eigen::Vector2d a = frame.rest[i].head<2>(), c = frame.rest[j].head<2>();
            if (j > i && crossZ(p, q, a) * crossZ(p, q, c) < 0.0 &&
                crossZ(a, c, p) * crossZ(a, c, q) < 0.0)
                frame.breakBond(i, j);
        }
    }
}

double meshArea(const Mesh& mesh) {
    double area = 0.0;
    for (const auto& t : mesh.triangles) {
        const Eigen::Vector3f& a = mesh.positions[t[0]];
        area += 0.5 * double((mesh.positions[t[1]] - a).cross(mesh.positions[t[2]] - a).norm());
    }
    return area;
}

// Each edge used by a single triangle, with that triangle.
std::vector<std::pair<Edge, std::size_t>> boundaryEdges(const Mesh& mesh) {
    const std::map<Edge, int> use = undirectedEdgeUse(mesh);
    std::vector<std::pair<Edge, std::size_t>> edges;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
        for (int e = 0; e < 3; ++e) {
            const Edge edge = std::minmax(mesh.triangles[t][e], mesh.triangles[t][(e + 1) % 3]);
            if (use.at(edge) == 1) edges.emplace_back(edge, t);
        }
    return edges;
}

struct Lips {
    double left = 0.0, right = 0.0;
};

// Lengths of the boundary edges of a mesh built at rest that lie within `reach` of the line
// x = c (the crack's lips), leaving out the outline's sides y = +-edge, split by the side of
// the line their triangle is on.
Lips lipLengths(const Mesh& mesh, double c, double side, double reach) {
    Lips lips;
    for (const auto& [edge, t] : boundaryEdges(mesh)) {
        const Eigen::Vector3f& a = mesh.positions[edge.first];
        const Eigen::Vector3f& b = mesh.positions[edge.second];
        if (std::abs(a.x() - c) > reach || std::abs(b.x() - c) > reach) continue;
        if (std::abs(std::abs(a.y()) - side) < 1e-6 && std::abs(std::abs(b.y()) - side) < 1e-6)
            continue;
        const auto& tri = mesh.triangles[t];
        const float centroid =
            (mesh.positions[tri[0]].x() + mesh.positions[tri[1]].x() + mesh.positions[tri[2]].x()) /
            3.0f;
        (centroid < c ? lips.left : lips.right) += double((b - a).norm());
    }
    return lips;
}

}  // namespace

TEST(LatticeCuts, ALoneBrokenBondLeavesNoHoleThroughTheSheet) {
    Sheet frame = membraneSheet(0.3, 0.2, kDx);
    const LatticeSurface surface(frame.view());
    const double intact = meshArea(surface.build(frame.view(), RenderSettings{}));
    frame.breakBond(frame.nearest(0.0, 0.0), frame.nearest(kDx, 0.0));
    const Mesh mesh = surface.build(frame.view(), RenderSettings{});
    expectWellFormed(mesh);
    // The two triangles along the bond stay, each with a slit to its centroid: nothing is lost.
    EXPECT_NEAR(meshArea(mesh), intact, 1e-9 * intact);
    EXPECT_EQ(componentCount(mesh), 1);
}

TEST(LatticeCuts, AFullySeparatedSheetGivesTwoPiecesWhoseLipsOpenWithTheParticles) {
    Sheet frame = membraneSheet(0.3, 0.2, kDx);
    const LatticeSurface surface(frame.view());
    const Eigen::Vector2d p(-0.2, -0.05), q(0.2, 0.07);  // across the sheet, askew to the lattice
    cutAlong(frame, p, q);
    const auto upper = [&](int i) { return crossZ(p, q, frame.rest[i].head<2>()) > 0.0; };
    const double opening = 0.3 * kDx;
    for (int i = 0; i < frame.size(); ++i)
        if (upper(i)) frame.positions[i].y() += opening;
    const Mesh mesh = surface.build(frame.view(), RenderSettings{});
    expectWellFormed(mesh);
    ASSERT_EQ(componentCount(mesh), 2);
    // Which piece each vertex is in, from the particle of the triangle it belongs to.
    std::vector<int> piece(mesh.positions.size(), -1);
    for (const auto& t : mesh.triangles) {
        int side = -1;
        for (auto v : t)
            if (v < std::uint32_t(frame.size())) side = upper(int(v));
        ASSERT_GE(side, 0) << "every piece has a particle";
        for (auto v : t) {
            EXPECT_TRUE(piece[v] < 0 || piece[v] == side) << "vertex " << v << " in both pieces";
            piece[v] = side;
        }
    }
    double gap = 1e30;
    for (std::size_t a = 0; a < piece.size(); ++a)
        for (std::size_t b = 0; b < piece.size(); ++b)
            if (piece[a] == 0 && piece[b] == 1)
                gap = std::min(gap, double((mesh.positions[a] - mesh.positions[b]).norm()));
    // Each lip vertex keeps its rest distance from its particle, so the lips part by the
    // separation's component along the broken bonds: at most the opening, and not nothing.
    EXPECT_GT(gap, 0.25 * opening);
    EXPECT_LE(gap, opening * (1.0 + 1e-5));
}

TEST(LatticeCuts, EachLipOfAStraightNotchAcrossTheLatticeIsAsLongAsTheNotch) {
    // A notch at right angles to the rows of the hexagonal lattice, its worst direction: the
    // lips of the dropped triangles zig-zag and come out 16% too long; cut, they are straight.
    constexpr double dx = 0.01;
    Sheet frame = membraneSheet(0.4, 0.3, dx);
    const LatticeSurface surface(frame.view());
    double bottom = 1e30;
    for (const auto& r : frame.rest) bottom = std::min(bottom, r.y());
    const double c = 0.25 * dx, length = 15 * dx;  // c between the particles of every row
    cutAlong(frame, {c, bottom - dx}, {c, bottom + length});
    const Mesh mesh = surface.build(frame.view(), RenderSettings{});
    expectWellFormed(mesh);
    const Lips lips = lipLengths(mesh, c, -bottom, 1.5 * dx);
    std::cout << "[ lips ] left " << lips.left / length << ", right " << lips.right / length
              << " of the notch's length\n";
    // The slit into the tip's triangle (about dx/3 each way) lies on one side of the line.
    EXPECT_NEAR(0.5 * (lips.left + lips.right), length, 0.03 * length);
    EXPECT_NEAR(lips.left, length, 0.08 * length);
    EXPECT_NEAR(lips.right, length, 0.08 * length);
}

TEST(LatticeOutline, AnIntactRectangleOfHexagonalLatticeHasStraightSides) {
    // Ten rows spacings high, so the rows fill the rectangle; the odd rows are dx/2 short of
    // its left and right sides.
    const double height = 10.0 * kDx * std::sqrt(3.0) / 2.0;
    const Sheet frame = membraneSheet(0.3, height, kDx);
    const Mesh mesh = LatticeSurface(frame.view()).build(frame.view(), RenderSettings{});
    double deviation = 0.0;
    int outline = 0;
    for (const auto& [edge, t] : boundaryEdges(mesh)) {
        for (auto v : {edge.first, edge.second}) {
            const Eigen::Vector3f& x = mesh.positions[v];
            deviation = std::max(deviation, std::min({std::abs(std::abs(x.x()) - 0.15),
                                                      std::abs(std::abs(x.y()) - height / 2)}));
            ++outline;
        }
    }
    EXPECT_GT(outline, 0);
    EXPECT_LT(deviation, 1e-6 * kDx);  // the dropped-triangle outline: dx/2
}

TEST(LatticeOutline, ANotchParticleFollowsItsNeighboursWhenTheSheetMoves) {
    // A rigid turn and shift of the sheet moves the straightened outline with it.
    const double height = 10.0 * kDx * std::sqrt(3.0) / 2.0;
    Sheet frame = membraneSheet(0.3, height, kDx);
    const LatticeSurface surface(frame.view());
    const Mesh atRest = surface.build(frame.view(), RenderSettings{});
    const Eigen::Matrix3d turn =
        Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    const Eigen::Vector3d shift(0.1, -0.2, 0.3);
    for (auto& x : frame.positions) x = turn * x + shift;
    const Mesh moved = surface.build(frame.view(), RenderSettings{});
    ASSERT_EQ(moved.positions.size(), atRest.positions.size());
    for (std::size_t v = 0; v < moved.positions.size(); ++v) {
        const Eigen::Vector3d expected = turn * atRest.positions[v].cast<double>() + shift;
        EXPECT_LT((moved.positions[v].cast<double>() - expected).norm(), 1e-6) << v;
    }
}

namespace {

// A torn membrane as in foil_tear: a 0.6 x 0.4 sheet (dx = 0.01) torn from the top edge along a
// bent crack, its two flaps lifted and pushed out of plane in opposite directions (a mode III
// tear) by an amount growing from the crack's tip to the top edge; damage updated.
class TornSheet {
public:
    TornSheet() : membrane_(params()) {
        auto& x = membrane_.positions();
        const auto& rest = membrane_.restPositions();
        const double tip = kCrack.back().y();
        for (std::size_t i = 0; i < x.size(); ++i) {
            const Eigen::Vector3d& r = rest[i];
            const double wave = 0.015 * std::sin(9.0 * r.x()) * std::cos(7.0 * r.y());
            const double s = std::clamp((r.y() - tip) / (0.2 - tip), 0.0, 1.0);
            const double flap = r.x() < crackX(r.y()) ? 1.0 : -1.0;
            x[i] = r + Eigen::Vector3d(0.02 * flap * s, 0.0, wave + 0.09 * flap * s * s);
        }
        membrane_.updateDamage();
    }

    FrameView view() const { return membrane_.view(1); }

private:
    static inline const std::array<Eigen::Vector2d, 4> kCrack = {
        Eigen::Vector2d(0.03, 0.21), Eigen::Vector2d(0.0, 0.12), Eigen::Vector2d(-0.05, 0.03),
        Eigen::Vector2d(-0.035, -0.07)};

    // x of the crack at height y (from its tip up to the top edge).
    static double crackX(double y) {
        for (std::size_t k = 0; k + 1 < kCrack.size(); ++k) {
            const Eigen::Vector2d& a = kCrack[k];
            const Eigen::Vector2d& b = kCrack[k + 1];
            if (y <= a.y() && y >= b.y())
                return a.x() + (b.x() - a.x()) * (a.y() - y) / (a.y() - b.y());
        }
        return kCrack.front().x();
    }

    static rend::sim::MembraneParams params() {
        rend::sim::MembraneParams p;
        p.sheet.size = {0.6, 0.4};
        p.sheet.dx = 0.01;
        p.notches = {rend::sim::Notch{{kCrack.begin(), kCrack.end()}}};
        return p;
    }

    rend::sim::Membrane membrane_;
};

}  // namespace

TEST(LatticeCuts, ATornMembraneMatchesItsReferenceImage) {
    const TornSheet sheet;
    const FrameView frame = sheet.view();
    RenderSettings settings;
    settings.width = 320;
    settings.height = 180;
    settings.colorBy = ColorBy::Damage;
    settings.colorRange = std::array<double, 2>{0.0, 0.5};
    settings.camera.position = Eigen::Vector3d(0.12, -0.22, 0.3);
    settings.camera.lookAt = Eigen::Vector3d(-0.01, 0.09, 0.0);
    settings.sun.direction = Eigen::Vector3d(-0.6, -0.4, 0.7);
    settings.groundHeight = -0.15;
    settings.pathTracing.samplesPerPixel = 8;
    settings.pathTracing.maxDepth = 3;
    const Mesh mesh = LatticeSurface(frame).build(frame, settings);
    EXPECT_EQ(componentCount(mesh), 1);  // torn, not through: the flaps meet below the tip
    rend::test::expectMatchesReference(rend::render::EmbreeRenderer().render(mesh, settings),
                                       "regress_embree_torn");
}

// ---- Mesh export -----------------------------------------------------------------------------

namespace {

// A 4 x 3 vertex grid in z = 0 with a different colour per vertex.
Mesh colouredGrid() {
    return rend::test::gridMesh(4, 3, [](int i, int j) {
        return rend::test::GridVertex{Eigen::Vector3f(0.1f * i, 0.1f * j, 0.0f),
                                      Eigen::Vector3f::UnitZ(),
                                      Eigen::Vector3f(i / 3.0f, j / 2.0f, 0.25f)};
    });
}

Eigen::Vector3f displayColor(const Eigen::Vector3f& linear) {
    return linear.array().pow(1.0f / 2.2f).matrix();
}

struct Imported {
    unsigned vertices = 0;
    unsigned faces = 0;
    aiVector3D min{1e30f, 1e30f, 1e30f}, max{-1e30f, -1e30f, -1e30f};
    // Colour of each imported vertex keyed by its rounded position.
    std::map<std::pair<int, int>, aiColor4D> colors;
};

/// A y-up point (glTF, OBJ) back in rend's z-up world, as Blender's importers turn it.
aiVector3D fromYUp(const aiVector3D& p) { return {p.x, -p.z, p.y}; }

/// `yUp`: the file is in the y-up frame (MeshExport.h toYUp); its points are turned back.
Imported importMesh(const fs::path& path, bool yUp = false) {
    Assimp::Importer importer;
    const aiScene* scene = importer.ReadFile(path.string(), aiProcess_JoinIdenticalVertices);
    Imported out;
    if (!scene) {
        ADD_FAILURE() << "assimp cannot read " << path << ": " << importer.GetErrorString();
        return out;
    }
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh& mesh = *scene->mMeshes[m];
        out.vertices += mesh.mNumVertices;
        out.faces += mesh.mNumFaces;
        for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
            const aiVector3D p = yUp ? fromYUp(mesh.mVertices[v]) : mesh.mVertices[v];
            out.min = aiVector3D(std::min(out.min.x, p.x), std::min(out.min.y, p.y),
                                 std::min(out.min.z, p.z));
            out.max = aiVector3D(std::max(out.max.x, p.x), std::max(out.max.y, p.y),
                                 std::max(out.max.z, p.z));
            if (mesh.mColors[0])
                out.colors[{int(std::lround(p.x * 10)), int(std::lround(p.y * 10))}] =
                    mesh.mColors[0][v];
        }
    }
    return out;
}

}  // namespace

TEST(MeshExport, ParsesFormatNames) {
    EXPECT_EQ(rend::render::parseMeshFormat("ply"), MeshFormat::Ply);
    EXPECT_EQ(rend::render::parseMeshFormat("OBJ"), MeshFormat::Obj);
    EXPECT_EQ(rend::render::parseMeshFormat(".glb"), MeshFormat::Glb);
    EXPECT_THROW(rend::render::parseMeshFormat("stl"), std::invalid_argument);
    EXPECT_THROW(rend::render::parseMeshFormat(""), std::invalid_argument);
}

TEST(MeshExport, EveryFormatRoundTripsThroughAssimp) {
    const Mesh mesh = colouredGrid();
    for (const char* name : {"ply", "obj", "glb"}) {
        SCOPED_TRACE(name);
        const MeshFormat format = rend::render::parseMeshFormat(name);
        const fs::path dir = scratchDir(std::string("export_") + name);
        const fs::path path = dir / (std::string("frame_0001.") + name);
        rend::render::exportMesh(mesh, path, format);
        ASSERT_TRUE(fs::exists(path));
        EXPECT_FALSE(anyTmpLeft(dir));
        if (format == MeshFormat::Obj) {
            EXPECT_TRUE(fs::exists(dir / "frame_0001.mtl"));
        }
        const Imported back = importMesh(path, format != MeshFormat::Ply);
        EXPECT_EQ(back.faces, mesh.triangles.size());
        EXPECT_EQ(back.vertices, mesh.positions.size());
        EXPECT_NEAR(back.min.x, 0.0f, 1e-6f);
        EXPECT_NEAR(back.max.x, 0.3f, 1e-6f);
        EXPECT_NEAR(back.max.y, 0.2f, 1e-6f);
        if (format == MeshFormat::Obj) continue;  // OBJ has no standard vertex colours
        ASSERT_EQ(back.colors.size(), mesh.positions.size());
        for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
            const auto& p = mesh.positions[v];
            const aiColor4D c =
                back.colors.at({int(std::lround(p.x() * 10)), int(std::lround(p.y() * 10))});
            // PLY stores display (gamma 2.2) bytes, GLB linear floats.
            const Eigen::Vector3f expected =
                format == MeshFormat::Ply ? displayColor(mesh.colors[v]) : mesh.colors[v];
            EXPECT_NEAR(c.r, expected.x(), 0.51 / 255);
            EXPECT_NEAR(c.g, expected.y(), 0.51 / 255);
            EXPECT_NEAR(c.b, expected.z(), 0.51 / 255);
        }
    }
}

TEST(MeshExport, PlyIsBinaryWithByteColours) {
    const fs::path dir = scratchDir("export_ply_header");
    rend::render::exportMesh(colouredGrid(), dir / "m.ply", MeshFormat::Ply);
    std::ifstream in(dir / "m.ply", std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t end = text.find("end_header\n");
    ASSERT_NE(end, std::string::npos);
    EXPECT_NE(text.find("format binary_little_endian 1.0"), std::string::npos);
    EXPECT_NE(text.find("property uchar red"), std::string::npos);
    // 12 vertices of 3 + 3 floats and 3 bytes, 12 faces of a count byte and 3 uint32.
    EXPECT_EQ(text.size() - (end + 11), 12u * 27u + 12u * 13u);
}

TEST(MeshExport, ObjReferencesItsMaterialLibraryByTheFinalName) {
    const fs::path dir = scratchDir("export_mtl");
    rend::render::exportMesh(colouredGrid(), dir / "sheet.obj", MeshFormat::Obj);
    std::ifstream in(dir / "sheet.obj");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("mtllib sheet.mtl"), std::string::npos);
    // Smooth faces, or Blender's importer ignores the normals it keeps.
    EXPECT_LT(text.find("\nvn "), text.find("\ns 1\n"));
    EXPECT_LT(text.find("\ns 1\n"), text.find("\nf "));
}

namespace {

/// Loose parts by shared vertex indices (as Blender counts them), over the vertices faces use.
std::size_t looseParts(std::size_t vertices,
                       const std::vector<std::array<std::uint32_t, 3>>& faces) {
    std::vector<std::uint32_t> parent(vertices);
    std::iota(parent.begin(), parent.end(), 0u);
    const auto root = [&](std::uint32_t v) {
        while (parent[v] != v) v = parent[v] = parent[parent[v]];
        return v;
    };
    std::set<std::uint32_t> used;
    for (const auto& f : faces) {
        used.insert(f.begin(), f.end());
        parent[root(f[0])] = root(f[1]);
        parent[root(f[1])] = root(f[2]);
    }
    std::set<std::uint32_t> roots;
    for (const std::uint32_t v : used) roots.insert(root(v));
    return roots.size();
}

struct IndexedFile {
    std::size_t vertices = 0;
    std::vector<std::array<std::uint32_t, 3>> faces;
};

IndexedFile readObjIndices(const fs::path& path) {
    IndexedFile out;
    std::ifstream in(path);
    for (std::string line; std::getline(in, line);) {
        if (line.starts_with("v ")) ++out.vertices;
        if (!line.starts_with("f ")) continue;
        std::istringstream words(line.substr(2));
        std::array<std::uint32_t, 3> face{};
        for (std::uint32_t& v : face) {
            std::string word;
            words >> word;
            v = std::uint32_t(std::stoul(word.substr(0, word.find('/')))) - 1;
        }
        out.faces.push_back(face);
    }
    return out;
}

IndexedFile readPlyIndices(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t body = text.find("end_header\n") + 11;
    IndexedFile out;
    std::size_t faces = 0, stride = 0;
    std::istringstream header(text.substr(0, body));
    for (std::string line; std::getline(header, line);) {
        if (line.starts_with("element vertex ")) out.vertices = std::stoul(line.substr(15));
        if (line.starts_with("element face ")) faces = std::stoul(line.substr(13));
        if (line.starts_with("property float")) stride += 4;
        if (line.starts_with("property uchar")) stride += 1;
    }
    std::size_t at = body + out.vertices * stride;
    for (std::size_t f = 0; f < faces; ++f, at += 13) {
        std::array<std::uint32_t, 3> face{};
        std::memcpy(face.data(), text.data() + at + 1, sizeof face);
        out.faces.push_back(face);
    }
    return out;
}

}  // namespace

// Issue 14: a crack's two lips coincide until it opens, and a bow-tie's two fans share a
// position, each with vertices of their own; assimp's OBJ exporter merged such vertices.
TEST(MeshExport, PlyAndObjKeepEveryVertexAndTheSameLooseParts) {
    Mesh mesh;
    mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0},  // piece A
                      {1, 0, 0}, {2, 0, 0}, {1, 1, 0},  // piece B: its vertex 3 lies on A's 1
                      {5, 5, 5}};                       // a particle no triangle holds any more
    mesh.normals.assign(mesh.positions.size(), Eigen::Vector3f(0, 0, 1));
    mesh.colors.assign(mesh.positions.size(), Eigen::Vector3f(0.5f, 0.5f, 0.5f));
    mesh.triangles = {{0, 1, 2}, {3, 4, 5}};
    ASSERT_EQ(looseParts(mesh.positions.size(), mesh.triangles), 2u);
    const fs::path dir = scratchDir("export_parts");
    rend::render::exportMesh(mesh, dir / "m.ply", MeshFormat::Ply);
    rend::render::exportMesh(mesh, dir / "m.obj", MeshFormat::Obj);
    for (const IndexedFile& file : {readPlyIndices(dir / "m.ply"), readObjIndices(dir / "m.obj")}) {
        EXPECT_EQ(file.vertices, mesh.positions.size()) << "vertex i stays vertex i";
        EXPECT_EQ(file.faces, mesh.triangles);
        EXPECT_EQ(looseParts(file.vertices, file.faces), 2u);
    }
}

namespace {

/// A PLY's vertex properties by name, each as floats (ints converted), from rend's layout.
std::map<std::string, std::vector<float>> readPlyVertexProperties(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t body = text.find("end_header\n") + 11;
    std::vector<std::pair<std::string, std::string>> properties;  // type, name
    std::size_t vertices = 0;
    std::istringstream header(text.substr(0, body));
    for (std::string line; std::getline(header, line);) {
        if (line.starts_with("element vertex ")) vertices = std::stoul(line.substr(15));
        if (line.starts_with("element face")) break;
        std::istringstream words(line);
        std::string word, type, name;
        if (words >> word >> type >> name && word == "property") properties.push_back({type, name});
    }
    std::map<std::string, std::vector<float>> values;
    std::size_t at = body;
    for (std::size_t v = 0; v < vertices; ++v)
        for (const auto& [type, name] : properties) {
            if (type == "uchar") {
                values[name].push_back(float(std::uint8_t(text[at])));
                at += 1;
            } else if (type == "int") {
                std::int32_t i;
                std::memcpy(&i, text.data() + at, 4);
                values[name].push_back(float(i));
                at += 4;
            } else {
                float f;
                std::memcpy(&f, text.data() + at, 4);
                values[name].push_back(f);
                at += 4;
            }
        }
    return values;
}

}  // namespace

// Issue 14: the PLY carries each vertex's particle id, velocity, damage and rest position (and
// its rest UV as s, t); the OBJ and GLB carry the UV. A torn frame's lip vertices belong to
// the particle of their side, at the crossing's rest position, so a texture runs on across the
// crack.
TEST(MeshExport, ExportsCarryTheParticlesIdsVelocitiesAndRestPositions) {
    Sheet frame = membraneSheet(0.3, 0.2, kDx);
    const LatticeSurface surface(frame.view());
    for (int i = 0; i < frame.size(); ++i) {
        frame.velocities[i] = Eigen::Vector3d(0.1 * i, -1.0, 0.5);
        for (int b = frame.offsets[i]; b < frame.offsets[i + 1]; ++b)
            if ((frame.rest[i].x() < 0.005) != (frame.rest[frame.partners[b]].x() < 0.005))
                frame.breakBond(i, frame.partners[b]);
    }
    const Mesh mesh = surface.build(frame.view(), RenderSettings{});
    ASSERT_GT(mesh.positions.size(), std::size_t(frame.size())) << "the crack has lips";
    const fs::path dir = scratchDir("export_attributes");
    rend::render::exportMesh(mesh, dir / "m.ply", MeshFormat::Ply);
    auto ply = readPlyVertexProperties(dir / "m.ply");
    ASSERT_EQ(ply["id"].size(), mesh.positions.size());
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
        const int id = int(ply["id"][v]);
        ASSERT_GE(id, 0);
        ASSERT_LT(id, frame.size());
        if (v < std::size_t(frame.size())) {
            ASSERT_EQ(id, int(v)) << "vertex i is particle i";
        }
        EXPECT_NEAR(ply["vx"][v], 0.1f * float(id), 1e-4f) << v;
        EXPECT_EQ(ply["vy"][v], -1.0f);
        const Eigen::Vector3f rest(ply["rest_x"][v], ply["rest_y"][v], ply["rest_z"][v]);
        // A lip lies on its particle's broken edge, a centroid in its particle's triangle.
        EXPECT_LE((rest - frame.rest[std::size_t(id)].cast<float>()).norm(), 1.0001 * kDx) << v;
        EXPECT_EQ(ply["damage"][v], 0.0f);
        EXPECT_GE(ply["s"][v], 0.0f);
        EXPECT_LE(ply["t"][v], 1.0f);
    }
    for (const MeshFormat format : {MeshFormat::Obj, MeshFormat::Glb}) {
        const fs::path path =
            dir / (std::string("m") + std::string(rend::render::meshFormatExtension(format)));
        rend::render::exportMesh(mesh, path, format);
        Assimp::Importer importer;
        const aiScene* scene = importer.ReadFile(path.string(), 0);
        ASSERT_TRUE(scene && scene->mNumMeshes == 1) << path;
        const aiMesh& m = *scene->mMeshes[0];
        ASSERT_TRUE(m.HasTextureCoords(0)) << path;
        // Vertex i of the GLB is the mesh's vertex i (particle i, for the particles), as in
        // the PLY and the OBJ (PlyAndObjKeepEveryVertexAndTheSameLooseParts; assimp's OBJ
        // reader makes a vertex of every face corner, so it cannot show it here).
        if (format == MeshFormat::Glb) {
            ASSERT_EQ(m.mNumVertices, mesh.positions.size());
        }
        for (unsigned v = 0; format == MeshFormat::Glb && v < m.mNumVertices; ++v)
            ASSERT_LT((Eigen::Vector3f(m.mVertices[v].x, m.mVertices[v].y, m.mVertices[v].z) -
                       rend::render::toYUp(mesh.positions[v]))
                          .norm(),
                      1e-5f)
                << path << " vertex " << v;
        float low = 1, high = 0;
        for (unsigned v = 0; v < m.mNumVertices; ++v) {
            low = std::min({low, m.mTextureCoords[0][v].x, m.mTextureCoords[0][v].y});
            high = std::max({high, m.mTextureCoords[0][v].x, m.mTextureCoords[0][v].y});
        }
        EXPECT_NEAR(low, 0.0f, 1e-6f) << path;
        EXPECT_NEAR(high, 1.0f, 1e-6f) << path;
    }
}

TEST(MeshExport, ExportedSurfacesKeepTheirTriangleCount) {
    const Sheet frame = membraneSheet(0.2, 0.2, kDx);
    const Mesh mesh = LatticeSurface(frame.view()).build(frame.view(), RenderSettings{});
    const fs::path dir = scratchDir("export_lattice");
    rend::render::exportMesh(mesh, dir / "lattice.glb", MeshFormat::Glb);
    EXPECT_EQ(importMesh(dir / "lattice.glb").faces, mesh.triangles.size());
}

TEST(MeshExport, FailureThrowsAndLeavesNothingBehind) {
    const fs::path dir = scratchDir("export_fail");
    std::ofstream(dir / "not_a_folder") << "x";
    EXPECT_THROW(
        rend::render::exportMesh(colouredGrid(), dir / "not_a_folder" / "m.ply", MeshFormat::Ply),
        std::runtime_error);
    EXPECT_FALSE(anyTmpLeft(dir));
}
