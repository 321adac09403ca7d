// Tests for render/: lattice surface extraction, colouring, PNG I/O, image comparison, the
// OSMesa preview renderer (against a reference image) and the library version report.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "TestSupport.h"
#include "render/ColorMap.h"
#include "render/Image.h"
#include "render/LatticeSurface.h"
#include "render/OsmesaRenderer.h"
#include "render/SplatSurface.h"
#include "render/Versions.h"
#include "sim/FrameView.h"
#include "tests/sim/ErodedElement.h"

namespace fs = std::filesystem;
using rend::render::ColorBy;
using rend::render::Image;
using rend::render::LatticeSurface;
using rend::render::RenderSettings;
using rend::sim::FrameView;
using rend::test::expectMatchesReference;
using rend::test::GridSheet;
using rend::test::pixel;
using rend::test::pixelDistance;
using rend::test::pixelsUnlike;
using rend::test::scratchDir;

namespace {

Image solidImage(int w, int h, std::uint8_t value) {
    return Image{w, h, std::vector<std::uint8_t>(std::size_t(w) * h * 3, value)};
}

double luminance(const Eigen::Vector3f& c) {
    return 0.2126 * c.x() + 0.7152 * c.y() + 0.0722 * c.z();
}

}  // namespace

// ---- LatticeSurface ------------------------------------------------------------------------

TEST(LatticeSurface, KeepsEveryTriangleWhenAllBondsAreIntact) {
    const GridSheet sheet(6, 5, 1.0);
    const LatticeSurface surface(sheet.view());
    EXPECT_EQ(surface.keptTriangles(sheet.view()).size(), sheet.triangles.size());
}

TEST(LatticeSurface, BrokenInteriorBondDropsBothAdjacentTriangles) {
    GridSheet sheet(6, 5, 1.0);
    const LatticeSurface surface(sheet.view());
    // The horizontal edge (2,2)-(3,2) has one triangle of cell (2,1) below it and one of
    // cell (2,2) above it.
    sheet.breakBond(sheet.id(2, 2), sheet.id(3, 2));
    const auto kept = surface.keptTriangles(sheet.view());
    EXPECT_EQ(kept.size(), sheet.triangles.size() - 2);
    for (int t : kept) {
        const std::set<int> corners(sheet.triangles[t].begin(), sheet.triangles[t].end());
        EXPECT_FALSE(corners.count(sheet.id(2, 2)) && corners.count(sheet.id(3, 2)));
    }
}

TEST(LatticeSurface, BrokenBoundaryBondDropsItsSingleTriangle) {
    GridSheet sheet(6, 5, 1.0);
    const LatticeSurface surface(sheet.view());
    sheet.breakBond(sheet.id(0, 0), sheet.id(1, 0));
    EXPECT_EQ(surface.keptTriangles(sheet.view()).size(), sheet.triangles.size() - 1);
}

TEST(LatticeSurface, ARemovedTriangleIsDroppedAloneWithItsBondsIntact) {
    // The FEM solver erodes elements: FrameView::keptTriangles drops exactly those triangles,
    // the neighbours that share their (intact) edges stay.
    const GridSheet sheet(6, 5, 1.0);
    const LatticeSurface surface(sheet.view());
    std::vector<std::uint8_t> flags(sheet.triangles.size(), 1);
    flags[7] = 0;
    rend::sim::FrameView view = sheet.view();
    view.keptTriangles = flags;
    const auto kept = surface.keptTriangles(view);
    EXPECT_EQ(kept.size(), sheet.triangles.size() - 1);
    EXPECT_EQ(std::count(kept.begin(), kept.end(), 7), 0);
}

TEST(Surfaces, AnErodedFemElementAppearsInNoSurface) {
    // Its sides are intact (its neighbours hold them): only FrameView::keptTriangles says it
    // is gone, and both the lattice and the splat surface read that.
    const rend::sim::MembraneParams p = rend::test::erodingSheet(0.0);
    rend::sim::Membrane m(p);
    const int t = rend::test::erodeOneElement(m, p);
    ASSERT_EQ(m.damageState().removedTriangleCount(), 1u);
    for (int e : m.damageState().triangleEdges(t)) ASSERT_TRUE(m.damageState().edgeIntact(e));
    const FrameView view = m.view(1);
    const std::size_t total = view.restTriangles.size();
    const auto kept = LatticeSurface(view).keptTriangles(view);
    EXPECT_EQ(kept.size(), total - 1);
    EXPECT_EQ(std::count(kept.begin(), kept.end(), t), 0);
    const auto splat = rend::render::SplatSurface(view).keptTriangles(view);
    ASSERT_EQ(splat.size(), total);
    EXPECT_EQ(splat[t], 0);
    EXPECT_EQ(std::size_t(std::count(splat.begin(), splat.end(), 1)), total - 1);
}

TEST(LatticeSurface, BuiltMeshSlitsBothTrianglesAlongABrokenBond) {
    GridSheet sheet(6, 5, 1.0);
    const LatticeSurface surface(sheet.view());
    sheet.breakBond(sheet.id(2, 2), sheet.id(3, 2));
    const auto mesh = surface.build(sheet.view(), RenderSettings{});
    // Each of the two becomes four triangles around its centroid, the slit between two of them.
    EXPECT_EQ(mesh.triangles.size(), sheet.triangles.size() - 2 + 8);
    EXPECT_EQ(mesh.positions.size(), mesh.normals.size());
    EXPECT_EQ(mesh.positions.size(), mesh.colors.size());
    for (const auto& t : mesh.triangles)
        for (auto v : t) EXPECT_LT(v, mesh.positions.size());
}

// A frame built into the last frame's mesh (app/FrameWriter keeps it) is the mesh built afresh:
// nothing of the earlier, larger one is left, with thickness, a crack and a colour map.
TEST(LatticeSurface, AFrameBuiltIntoTheLastFramesMeshIsTheFreshMesh) {
    GridSheet sheet(8, 7, 1.0, [](double x, double y) { return 0.1 * x * y; });
    const LatticeSurface surface(sheet.view());
    RenderSettings settings;
    settings.thickness = 0.2;
    for (int i = 1; i < 7; ++i) sheet.breakBond(sheet.id(i, 3), sheet.id(i, 4));
    rend::render::Mesh reused =
        surface.build(sheet.view(), settings);  // cracked and thick: the larger
    GridSheet later(8, 7, 1.0, [](double x, double y) { return 0.2 * x - 0.1 * y; });
    later.breakBond(later.id(2, 2), later.id(3, 2));
    settings.thickness = 0.0;
    surface.build(later.view(), settings, reused);
    const rend::render::Mesh fresh = surface.build(later.view(), settings);
    ASSERT_LT(fresh.positions.size(), reused.positions.capacity());  // storage was kept
    EXPECT_EQ(reused.positions, fresh.positions);
    EXPECT_EQ(reused.normals, fresh.normals);
    EXPECT_EQ(reused.colors, fresh.colors);
    EXPECT_EQ(reused.layers, fresh.layers);
    EXPECT_EQ(reused.theta, fresh.theta);
    EXPECT_EQ(reused.triangles, fresh.triangles);
    ASSERT_EQ(reused.points.size(), fresh.points.size());
    for (std::size_t v = 0; v < fresh.points.size(); ++v) {
        EXPECT_EQ(reused.points[v].id, fresh.points[v].id);
        EXPECT_EQ(reused.points[v].rest, fresh.points[v].rest);
    }
}

TEST(LatticeSurface, NormalsOfAFlatSheetAtRestAreUnitAndPointUp) {
    const GridSheet sheet(6, 5, 0.5);
    const auto mesh = LatticeSurface(sheet.view()).build(sheet.view(), RenderSettings{});
    for (const auto& n : mesh.normals) {
        EXPECT_NEAR(n.norm(), 1.0f, 1e-6f);
        EXPECT_NEAR(n.z(), 1.0f, 1e-6f);
    }
}

TEST(LatticeSurface, IsolatedVertexGetsTheUpNormal) {
    GridSheet sheet(3, 3, 1.0);
    const LatticeSurface surface(sheet.view());
    // Removing the corner particle's one triangle (as erosion does) leaves it in none.
    sheet.kept.assign(sheet.triangles.size(), 1);
    for (std::size_t t = 0; t < sheet.triangles.size(); ++t)
        if (std::count(sheet.triangles[t].begin(), sheet.triangles[t].end(), 0)) sheet.kept[t] = 0;
    sheet.positions[0].z() = 5.0;
    const auto mesh = surface.build(sheet.view(), RenderSettings{});
    EXPECT_TRUE(mesh.normals[0].isApprox(Eigen::Vector3f::UnitZ()));
}

namespace {

// Removes (as erosion does, bonds intact) the triangles of every cell not kept.
template <typename KeepCell>
void keepOnlyCells(GridSheet& sheet, KeepCell keep) {
    sheet.kept.assign(sheet.triangles.size(), 1);
    for (int j = 0; j + 1 < sheet.ny; ++j)
        for (int i = 0; i + 1 < sheet.nx; ++i)
            if (!keep(i, j))
                for (int t : {2 * (j * (sheet.nx - 1) + i), 2 * (j * (sheet.nx - 1) + i) + 1})
                    sheet.kept[t] = 0;
}

// Union-find over mesh vertices joined by triangles; returns each triangle's component root.
std::vector<int> triangleComponents(const rend::render::Mesh& mesh) {
    std::vector<int> parent(mesh.positions.size());
    for (std::size_t v = 0; v < parent.size(); ++v) parent[v] = static_cast<int>(v);
    auto find = [&](int v) {
        while (parent[v] != v) v = parent[v] = parent[parent[v]];
        return v;
    };
    for (const auto& t : mesh.triangles) {
        parent[find(int(t[1]))] = find(int(t[0]));
        parent[find(int(t[2]))] = find(int(t[0]));
    }
    std::vector<int> roots;
    for (const auto& t : mesh.triangles) roots.push_back(find(int(t[0])));
    return roots;
}

void expectIndicesInRange(const rend::render::Mesh& mesh) {
    ASSERT_EQ(mesh.positions.size(), mesh.normals.size());
    ASSERT_EQ(mesh.positions.size(), mesh.colors.size());
    for (const auto& t : mesh.triangles)
        for (auto v : t) ASSERT_LT(v, mesh.positions.size());
}

}  // namespace

TEST(LatticeSurfaceCracks, IntactSheetHasNoExtraVertices) {
    const GridSheet sheet(6, 5, 1.0);
    const auto mesh = LatticeSurface(sheet.view()).build(sheet.view(), RenderSettings{});
    EXPECT_EQ(mesh.positions.size(), sheet.positions.size());
    EXPECT_EQ(triangleComponents(mesh).size(), sheet.triangles.size());
}

TEST(LatticeSurfaceCracks, SlitEndingInsideTheSheetAddsTwoLipVerticesAndTwoCentroids) {
    // One broken bond opens a slit; every particle's triangles still form one fan.
    GridSheet sheet(6, 5, 1.0);
    const LatticeSurface surface(sheet.view());
    sheet.breakBond(sheet.id(2, 2), sheet.id(3, 2));
    EXPECT_EQ(surface.build(sheet.view(), RenderSettings{}).positions.size(),
              sheet.positions.size() + 4);
}

TEST(LatticeSurfaceCracks, BowtieParticleGetsExactlyOneCopy) {
    // Keep the lower-left and upper-right quadrants of a 5 x 5 sheet: they touch only at (2,2).
    GridSheet sheet(5, 5, 1.0);
    const LatticeSurface surface(sheet.view());
    keepOnlyCells(sheet, [](int i, int j) { return (i < 2) == (j < 2); });
    sheet.positions[sheet.id(2, 2)] = Eigen::Vector3d(0.25, -0.5, 0.75);
    RenderSettings settings;
    settings.colorBy = ColorBy::Speed;
    sheet.velocities[sheet.id(2, 2)] = Eigen::Vector3d(0.0, 0.0, 1.0);
    const auto mesh = surface.build(sheet.view(), settings);
    expectIndicesInRange(mesh);
    ASSERT_EQ(mesh.positions.size(), sheet.positions.size() + 1);
    const std::size_t pivot = sheet.id(2, 2);
    EXPECT_EQ(mesh.positions.back(), mesh.positions[pivot]);
    EXPECT_EQ(mesh.colors.back(), mesh.colors[pivot]);
    // Each quadrant's triangles at the pivot use one of the two vertices, never both.
    std::set<std::uint32_t> lowerLeft, upperRight;
    for (const auto& t : mesh.triangles) {
        for (auto v : t) {
            if (v != pivot && v != mesh.positions.size() - 1) continue;
            const bool upper = std::all_of(t.begin(), t.end(), [&](std::uint32_t w) {
                return w >= sheet.positions.size() || sheet.rest[w].x() >= 0.0;
            });
            (upper ? upperRight : lowerLeft).insert(v);
        }
    }
    EXPECT_EQ(lowerLeft.size(), 1u);
    EXPECT_EQ(upperRight.size(), 1u);
    EXPECT_NE(*lowerLeft.begin(), *upperRight.begin());
}

TEST(LatticeSurfaceCracks, SheetCutFullyAcrossFallsIntoTwoPiecesSharingNoVertex) {
    // Break every bond crossing the anti-diagonal line i + j = n - 1.5, between particles. (A
    // line through particles would leave them bonded to both sides: no separation.)
    constexpr int n = 7;
    GridSheet sheet(n, n, 1.0);
    const LatticeSurface surface(sheet.view());
    auto side = [&](int p) { return p % n + p / n > n - 1.5 ? 1 : -1; };
    for (int a = 0; a < n * n; ++a)
        for (int b = sheet.offsets[a]; b < sheet.offsets[a + 1]; ++b)
            if (side(a) * side(sheet.partners[b]) < 0) sheet.breakBond(a, sheet.partners[b]);
    // Tilt the upper half about the crack; the lower half stays flat.
    for (int p = 0; p < n * n; ++p)
        if (side(p) > 0) sheet.positions[p].z() = 0.5 * (p % n + p / n - (n - 1.5));
    const auto mesh = surface.build(sheet.view(), RenderSettings{});
    expectIndicesInRange(mesh);

    const std::vector<int> roots = triangleComponents(mesh);
    const std::set<int> components(roots.begin(), roots.end());
    ASSERT_EQ(components.size(), 2u);
    std::map<std::uint32_t, int> owner;  // vertex -> component
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        for (auto v : mesh.triangles[t]) {
            const auto [it, inserted] = owner.emplace(v, roots[t]);
            EXPECT_EQ(it->second, roots[t]) << "vertex " << v << " is in both pieces";
        }
    }
    // Normals stay unit, and the flat half's are exactly up even where it touches the tilted
    // half: no shading bleeds across the crack.
    // Triangle 0 is in cell (0, 0), on the flat side.
    for (const auto& [v, root] : owner) {
        EXPECT_NEAR(mesh.normals[v].norm(), 1.0f, 1e-6f);
        if (root == roots.front()) {
            EXPECT_NEAR(mesh.normals[v].z(), 1.0f, 1e-6f) << v;
        }
    }
}

// ---- Colour map ----------------------------------------------------------------------------

TEST(ColorMap, RunsFromDarkBlueToBrightYellow) {
    const Eigen::Vector3f low = rend::render::colormap(0.0);
    const Eigen::Vector3f high = rend::render::colormap(1.0);
    EXPECT_GT(low.z(), low.y());    // blue-ish start
    EXPECT_GT(high.x(), high.z());  // yellow end: red and green well above blue
    EXPECT_GT(high.y(), high.z());
    EXPECT_LT(luminance(low), 0.05);
    EXPECT_GT(luminance(high), 0.6);
}

TEST(ColorMap, BrightnessRisesMonotonically) {
    double previous = -1.0;
    for (int k = 0; k <= 64; ++k) {
        const double l = luminance(rend::render::colormap(k / 64.0));
        EXPECT_GT(l, previous) << "at t = " << k / 64.0;
        previous = l;
    }
}

TEST(ColorMap, ClampsOutOfRangeInputsToTheEndpoints) {
    using rend::render::colormap;
    EXPECT_TRUE(colormap(-3.0).isApprox(colormap(0.0)));
    EXPECT_TRUE(colormap(7.0).isApprox(colormap(1.0)));
    EXPECT_TRUE(colormap(std::nan("")).isApprox(colormap(0.0)));
}

TEST(ColorMap, StrainOfAUniformlyStretchedSheetIsTheStretch) {
    GridSheet sheet(6, 5, 1.0);
    for (std::size_t i = 0; i < sheet.positions.size(); ++i)
        sheet.positions[i] = 1.1 * sheet.rest[i];
    const auto strain = rend::render::particleField(sheet.view(), ColorBy::Strain);
    ASSERT_EQ(strain.size(), sheet.positions.size());
    for (double s : strain) EXPECT_NEAR(s, 0.1, 1e-12);
}

TEST(ColorMap, StrainIgnoresBrokenBonds) {
    GridSheet sheet(3, 1, 1.0);
    sheet.positions[2].x() += 1.0;  // stretch only the (1,2) bond, then break it
    sheet.breakBond(1, 2);
    const auto strain = rend::render::particleField(sheet.view(), ColorBy::Strain);
    EXPECT_NEAR(strain[0], 0.0, 1e-12);
    EXPECT_NEAR(strain[1], 0.0, 1e-12);
    EXPECT_NEAR(strain[2], 0.0, 1e-12);  // no intact bonds left: no load
}

TEST(ColorMap, SpeedIsTheVelocityMagnitude) {
    GridSheet sheet(2, 2, 1.0);
    sheet.velocities[3] = Eigen::Vector3d(3.0, 0.0, 4.0);
    const auto speed = rend::render::particleField(sheet.view(), ColorBy::Speed);
    EXPECT_DOUBLE_EQ(speed[0], 0.0);
    EXPECT_DOUBLE_EQ(speed[3], 5.0);
    EXPECT_TRUE(rend::render::particleField(sheet.view(), ColorBy::None).empty());
}

TEST(ColorMap, ColoursUseAlbedoWithoutAFieldAndTheFieldMaximumOtherwise) {
    GridSheet sheet(2, 2, 1.0);
    sheet.velocities[3] = Eigen::Vector3d(0.0, 0.0, 2.0);
    RenderSettings settings;
    auto colors = rend::render::particleColors(sheet.view(), settings);
    EXPECT_TRUE(colors[0].isApprox(settings.albedo.cast<float>()));
    settings.colorBy = ColorBy::Speed;
    colors = rend::render::particleColors(sheet.view(), settings);
    EXPECT_TRUE(colors[0].isApprox(rend::render::colormap(0.0)));
    EXPECT_TRUE(colors[3].isApprox(rend::render::colormap(1.0)));
    settings.colorRange = std::array<double, 2>{0.0, 4.0};
    colors = rend::render::particleColors(sheet.view(), settings);
    EXPECT_TRUE(colors[3].isApprox(rend::render::colormap(0.5)));
}

TEST(ColorMap, AllZeroFieldMapsToTheLowEnd) {
    const GridSheet sheet(2, 2, 1.0);
    RenderSettings settings;
    settings.colorBy = ColorBy::Speed;
    for (const auto& c : rend::render::particleColors(sheet.view(), settings))
        EXPECT_TRUE(c.isApprox(rend::render::colormap(0.0)));
}

TEST(ColorMap, ThetaRunsFromLightRedToDarkRed) {
    using rend::render::thetaColormap;
    const Eigen::Vector3f light = thetaColormap(0.0);
    const Eigen::Vector3f dark = thetaColormap(1.0);
    for (const Eigen::Vector3f& c : {light, dark}) {
        EXPECT_GT(c.x(), c.y());  // red dominates at both ends
        EXPECT_GT(c.x(), c.z());
    }
    EXPECT_GT(luminance(light), 0.6);  // a light, slightly pink material
    EXPECT_GT(light.y(), 0.5f * light.x());
    EXPECT_LT(luminance(dark), 0.06);
    EXPECT_LT(dark.y(), 0.05f * dark.x());  // a deep, saturated red
    EXPECT_GT(dark.x(), 0.1f);
    EXPECT_TRUE(thetaColormap(-1.0).isApprox(light));
    EXPECT_TRUE(thetaColormap(2.0).isApprox(dark));
    EXPECT_TRUE(thetaColormap(std::nan("")).isApprox(light));
}

TEST(ColorMap, ThetaBrightnessFallsMonotonically) {
    double previous = 2.0;
    for (int k = 0; k <= 64; ++k) {
        const double l = luminance(rend::render::thetaColormap(k / 64.0));
        EXPECT_LT(l, previous) << "at t = " << k / 64.0;
        previous = l;
    }
}

TEST(ColorMap, ThetaAndDamageFieldsAreTheFrameValuesOrZeros) {
    GridSheet sheet(2, 2, 1.0);
    const std::vector<double> theta{0.0, 0.5, 1.5, 3.0};
    const std::vector<double> damage{0.25, 0.0, 1.0, 0.5};
    EXPECT_EQ(rend::render::particleField(sheet.view(), ColorBy::Theta),
              std::vector<double>(4, 0.0));
    EXPECT_EQ(rend::render::particleField(sheet.view(), ColorBy::Damage),
              std::vector<double>(4, 0.0));
    FrameView view = sheet.view();
    view.theta = theta;
    view.damage = damage;
    EXPECT_EQ(rend::render::particleField(view, ColorBy::Theta), theta);
    EXPECT_EQ(rend::render::particleField(view, ColorBy::Damage), damage);
}

TEST(ColorMap, ThetaAsThePaperMapUsesTheRedMapAndDamageViridis) {
    GridSheet sheet(2, 2, 1.0);
    const std::vector<double> values{0.0, 1.0, 2.0, 4.0};
    FrameView view = sheet.view();
    view.theta = values;
    view.damage = values;
    RenderSettings settings;
    settings.colorBy = ColorBy::Theta;
    settings.thetaStyle = rend::render::ThetaStyle::PaperMap;
    auto colors = rend::render::particleColors(view, settings);
    EXPECT_TRUE(colors[0].isApprox(rend::render::thetaColormap(0.0)));
    EXPECT_TRUE(colors[2].isApprox(rend::render::thetaColormap(0.5)));
    EXPECT_TRUE(colors[3].isApprox(rend::render::thetaColormap(1.0)));
    settings.colorBy = ColorBy::Damage;
    settings.colorRange = std::array<double, 2>{0.0, 8.0};
    colors = rend::render::particleColors(view, settings);
    EXPECT_TRUE(colors[3].isApprox(rend::render::colormap(0.5)));
    // A frame without theta is uniformly the light end, not an error.
    settings.colorBy = ColorBy::Theta;
    settings.colorRange.reset();
    for (const auto& c : rend::render::particleColors(sheet.view(), settings))
        EXPECT_TRUE(c.isApprox(rend::render::thetaColormap(0.0)));
}

// ---- PNG I/O and comparison ----------------------------------------------------------------

TEST(Image, PngRoundTripPreservesEveryPixel) {
    Image image = solidImage(7, 5, 0);
    for (std::size_t k = 0; k < image.rgb.size(); ++k) image.rgb[k] = std::uint8_t(k * 37 % 256);
    const fs::path path = scratchDir() / "round_trip.png";
    rend::render::writePngAtomic(image, path);
    const Image back = rend::render::readPng(path);
    EXPECT_EQ(back.width, image.width);
    EXPECT_EQ(back.height, image.height);
    EXPECT_EQ(back.rgb, image.rgb);
}

// A frame's size, smooth with some noise as a render is: zlib's stream (render/Image.cpp) over
// stb's row filters reads back to every byte.
TEST(Image, AFrameSizedPngRoundTripsThroughZlib) {
    Image image = solidImage(960, 540, 0);
    std::uint32_t noise = 12345;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            for (int k = 0; k < 3; ++k) {
                noise = noise * 1664525u + 1013904223u;
                const int smooth = (x * (k + 1) / 8 + y / 3) % 256;
                image.rgb[(std::size_t(y) * image.width + x) * 3 + k] =
                    std::uint8_t((smooth + int(noise >> 30)) % 256);
            }
    const fs::path path = scratchDir() / "frame_sized.png";
    rend::render::writePngAtomic(image, path);
    EXPECT_LT(fs::file_size(path), image.rgb.size() / 2);  // compressed
    const Image back = rend::render::readPng(path);
    EXPECT_EQ(back.width, image.width);
    EXPECT_EQ(back.height, image.height);
    EXPECT_EQ(back.rgb, image.rgb);
}

TEST(Image, AtomicWriteLeavesNoTemporaryFile) {
    const fs::path path = scratchDir() / "atomic.png";
    fs::remove(path);
    rend::render::writePngAtomic(solidImage(4, 3, 128), path);
    EXPECT_TRUE(fs::exists(path));
    EXPECT_FALSE(fs::exists(fs::path(path.string() + ".tmp")));
}

TEST(Image, WritingIntoAMissingDirectoryThrows) {
    const fs::path path = scratchDir() / "no" / "such" / "dir" / "x.png";
    EXPECT_THROW(rend::render::writePngAtomic(solidImage(2, 2, 0), path), std::runtime_error);
}

TEST(Image, ReadingAMissingFileThrows) {
    EXPECT_THROW(rend::render::readPng(scratchDir() / "missing.png"), std::runtime_error);
}

TEST(Image, IdenticalImagesHaveNoFailingPixels) {
    const Image a = solidImage(8, 6, 90);
    const auto diff = rend::render::compareImages(a, a, 0);
    EXPECT_EQ(diff.failingFraction, 0.0);
    EXPECT_EQ(diff.maxDifference, 0);
}

TEST(Image, OneChangedPixelFailsExactlyThatFraction) {
    const Image a = solidImage(8, 6, 90);
    Image b = a;
    b.rgb[(2 * 8 + 3) * 3 + 1] = 200;
    const auto diff = rend::render::compareImages(a, b, 8);
    EXPECT_DOUBLE_EQ(diff.failingFraction, 1.0 / (8 * 6));
    EXPECT_EQ(diff.maxDifference, 110);
    const std::uint8_t* red = &diff.diff.rgb[(2 * 8 + 3) * 3];
    EXPECT_EQ(red[0], 255);
    EXPECT_EQ(red[1], 0);
    EXPECT_EQ(diff.diff.rgb[0], 27);  // passing pixels darkened to 30 %
}

TEST(Image, DifferencesWithinToleranceDoNotFail) {
    const Image a = solidImage(4, 4, 100);
    const Image b = solidImage(4, 4, 108);
    EXPECT_EQ(rend::render::compareImages(a, b, 8).failingFraction, 0.0);
    EXPECT_EQ(rend::render::compareImages(a, b, 7).failingFraction, 1.0);
}

TEST(Image, SizeMismatchFailsEverything) {
    const auto diff = rend::render::compareImages(solidImage(4, 4, 0), solidImage(4, 5, 0), 8);
    EXPECT_EQ(diff.failingFraction, 1.0);
}

// ---- OSMesa renderer -----------------------------------------------------------------------

namespace {

// A 2.3 x 1.5 sheet with a gentle standing wave along x; the stretched flanks of the wave
// light up in the strain colouring.
GridSheet wavySheet() {
    return GridSheet(24, 16, 0.1, [](double x, double) {
        return 0.15 * std::sin(2.0 * std::numbers::pi * x / 1.2);
    });
}

RenderSettings smallSettings() {
    RenderSettings settings;
    settings.width = 160;
    settings.height = 90;
    settings.supersample = 2;
    settings.colorBy = ColorBy::Strain;
    settings.colorRange = std::array<double, 2>{0.0, 0.14};
    // Low enough that the horizon, where the ground fades into the background, is in frame.
    settings.camera.position = Eigen::Vector3d(0.6, -3.0, 1.0);
    settings.camera.lookAt = Eigen::Vector3d(0.0, 0.0, -0.1);
    return settings;
}

Image renderWavySheet(const RenderSettings& settings) {
    const GridSheet sheet = wavySheet();
    const auto mesh = LatticeSurface(sheet.view()).build(sheet.view(), settings);
    rend::render::OsmesaRenderer renderer;
    return renderer.render(mesh, settings);
}

}  // namespace

TEST(OsmesaRenderer, ProducesAnImageOfTheRequestedSize) {
    const Image image = renderWavySheet(smallSettings());
    EXPECT_EQ(image.width, 160);
    EXPECT_EQ(image.height, 90);
    EXPECT_EQ(image.rgb.size(), 160u * 90u * 3u);
}

TEST(OsmesaRenderer, DrawsTheSheetOverTheBackground) {
    RenderSettings settings = smallSettings();
    settings.ground = false;
    const Image image = renderWavySheet(settings);
    const std::uint8_t* corner = pixel(image, 0, 0);
    // The camera looks at the sheet's centre, so the centre pixel must be sheet, not sky.
    EXPECT_GT(pixelDistance(pixel(image, 80, 45), corner), 30);
    EXPECT_GT(pixelsUnlike(image, corner, 8), image.width * image.height / 10);
}

TEST(OsmesaRenderer, EmptyMeshWithoutGroundIsPureBackground) {
    RenderSettings settings = smallSettings();
    settings.ground = false;
    rend::render::OsmesaRenderer renderer;
    const Image image = renderer.render(rend::render::Mesh{}, settings);
    for (int y = 0; y < image.height; y += 7)
        for (int x = 0; x < image.width; x += 7)
            ASSERT_EQ(pixelDistance(pixel(image, x, y), pixel(image, 0, 0)), 0);
}

TEST(OsmesaRenderer, SameInputGivesIdenticalPixelsAndResizesBetweenCalls) {
    const GridSheet sheet = wavySheet();
    RenderSettings settings = smallSettings();
    const auto mesh = LatticeSurface(sheet.view()).build(sheet.view(), settings);
    rend::render::OsmesaRenderer renderer;
    const Image first = renderer.render(mesh, settings);
    settings.width = 64;
    settings.height = 48;
    EXPECT_EQ(renderer.render(mesh, settings).width, 64);
    settings = smallSettings();
    EXPECT_EQ(renderer.render(mesh, settings).rgb, first.rgb);
}

TEST(OsmesaRenderer, MatchesTheReferenceImage) {
    expectMatchesReference(renderWavySheet(smallSettings()), "osmesa_sheet");
}

// ---- Versions ------------------------------------------------------------------------------

TEST(Versions, ReportsEveryRenderingLibrary) {
    const auto versions = rend::render::renderLibraryVersions();
    auto find = [&](const std::string& name) {
        for (const auto& [lib, version] : versions)
            if (lib == name) return version;
        return std::string();
    };
    for (const char* lib : {"Embree", "OpenVDB", "assimp", "OSMesa", "stb", "zlib"}) {
        EXPECT_FALSE(find(lib).empty()) << lib;
        std::cout << "  " << lib << ": " << find(lib) << "\n";
    }
    EXPECT_NE(find("Embree").find('.'), std::string::npos);
    const std::string gl = find("OSMesa");
    EXPECT_TRUE(gl.find("llvmpipe") != std::string::npos ||
                gl.find("softpipe") != std::string::npos)
        << gl;
}
