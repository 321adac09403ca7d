// Image regression for every renderer x surface: one fixed frame of a small notched sheet,
// rendered as lattice, splat and vdb surface by OSMesa and by Embree, each compared with
// tests/data/regress_<renderer>_<surface>.png (REND_REGENERATE_REFERENCES=1 rewrites them).

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <tuple>
#include <variant>

#include "TestSupport.h"
#include "render/ColliderMesh.h"
#include "render/EmbreeRenderer.h"
#include "render/Geometry.h"
#include "render/Image.h"
#include "render/LatticeSurface.h"
#include "render/OsmesaRenderer.h"
#include "render/RenderSettings.h"
#include "render/SplatSurface.h"
#include "render/VdbSurface.h"
#include "sim/FrameView.h"
#include "sim/Membrane.h"

namespace render = rend::render;
namespace sim = rend::sim;
using render::SurfaceKind;

namespace {

// The notch runs along y = kNotchY from the left edge (x = -0.3) to the centre. Its upper lip
// is lifted by kOpening at the edge, closing linearly towards the tip: wide enough that the
// gap shows between the splat discs (radius 0.6 dx), and gentle enough in x that the discs
// still close the sheet ahead of the tip, where the bonds are intact.
constexpr double kNotchY = 0.005;
constexpr double kOpening = 0.04;

// A 0.6 x 0.4 simulated sheet with a gentle wave and an open notch, its damage field updated:
// the same frame for every surface and renderer.
class NotchedSheet {
public:
    NotchedSheet() : membrane_(params()) {
        auto& x = membrane_.positions();
        const auto& rest = membrane_.restPositions();
        for (std::size_t i = 0; i < x.size(); ++i) {
            const Eigen::Vector3d& r = rest[i];
            x[i] =
                r + Eigen::Vector3d(0.0, 0.0, 0.03 * std::sin(8.0 * r.x()) * std::cos(6.0 * r.y()));
            if (r.y() > kNotchY) x[i].y() += kOpening * std::clamp(-r.x() / 0.3, 0.0, 1.0);
        }
        membrane_.updateDamage();
    }

    sim::FrameView view() const { return membrane_.view(1); }

private:
    static sim::MembraneParams params() {
        sim::MembraneParams p;
        p.sheet.size = {0.6, 0.4};
        p.sheet.dx = 0.02;
        p.notches = {sim::Notch{{{-0.31, kNotchY}, {0.0, kNotchY}}}};
        return p;
    }

    sim::Membrane membrane_;
};

// Damage coloured, from above the front edge, 160 x 90; the path tracer at 8 samples.
render::RenderSettings frameSettings() {
    render::RenderSettings settings;
    settings.width = 160;
    settings.height = 90;
    settings.colorBy = render::ColorBy::Damage;
    settings.colorRange = std::array<double, 2>{0.0, 0.5};
    settings.camera.position = Eigen::Vector3d(0.05, -0.45, 0.6);
    settings.camera.lookAt = Eigen::Vector3d(0.0, -0.01, 0.0);
    settings.sun.direction =
        Eigen::Vector3d(-0.8, -0.3, 0.6);  // low from the left: the wave shades
    settings.groundHeight = -0.1;
    settings.pathTracing.samplesPerPixel = 8;
    settings.pathTracing.maxDepth = 3;
    return settings;
}

enum class Renderer { Osmesa, Embree };

std::string name(Renderer renderer) { return renderer == Renderer::Osmesa ? "osmesa" : "embree"; }

std::string name(SurfaceKind surface) {
    static const std::map<SurfaceKind, std::string> names = {{SurfaceKind::Lattice, "lattice"},
                                                             {SurfaceKind::Splat, "splat"},
                                                             {SurfaceKind::Vdb, "vdb"}};
    return names.at(surface);
}

// The frame's surface as the renderer takes it: OSMesa rasterises triangles only, so splats
// reach it as disc fans (render::splatsToMesh).
render::Geometry surfaceGeometry(SurfaceKind surface, Renderer renderer) {
    const NotchedSheet sheet;
    const sim::FrameView frame = sheet.view();
    const render::RenderSettings settings = frameSettings();
    if (surface == SurfaceKind::Lattice)
        return render::LatticeSurface(frame).build(frame, settings);
    if (surface == SurfaceKind::Vdb)
        return render::VdbSurface(frame, render::VdbSettings{}).build(frame, settings);
    const render::Splats splats = render::SplatSurface(frame).build(frame, settings);
    if (renderer == Renderer::Osmesa) return render::splatsToMesh(splats);
    return splats;
}

render::Image renderWith(Renderer renderer, const render::Geometry& geometry) {
    const render::RenderSettings settings = frameSettings();
    if (renderer == Renderer::Embree) return render::EmbreeRenderer().render(geometry, settings);
    return render::OsmesaRenderer().render(std::get<render::Mesh>(geometry), settings);
}

class EveryRendererAndSurface : public ::testing::TestWithParam<std::tuple<Renderer, SurfaceKind>> {
};

}  // namespace

TEST_P(EveryRendererAndSurface, MatchesItsReferenceImageAndCoversMoreThanTheBackground) {
    const auto [renderer, surface] = GetParam();
    const render::Image image = renderWith(renderer, surfaceGeometry(surface, renderer));
    const render::Image background = renderWith(renderer, render::Mesh{});
    const double coverage =
        double(rend::test::pixelsDiffering(image, background, 8)) / (image.width * image.height);
    EXPECT_GT(coverage, 0.05);
    rend::test::expectMatchesReference(image, "regress_" + name(renderer) + "_" + name(surface));
}

INSTANTIATE_TEST_SUITE_P(RenderRegression, EveryRendererAndSurface,
                         ::testing::Combine(::testing::Values(Renderer::Osmesa, Renderer::Embree),
                                            ::testing::Values(SurfaceKind::Lattice,
                                                              SurfaceKind::Splat,
                                                              SurfaceKind::Vdb)),
                         [](const auto& info) {
                             return name(std::get<0>(info.param)) + "_" +
                                    name(std::get<1>(info.param));
                         });

namespace {

// A 0.4 m sheet dropped onto a ball on the ground, with self-contact, half a second on: the
// frame with contact the renderers draw (the sheet draped over the ball, the ball in its look).
sim::Membrane drapedSheet() {
    sim::MembraneParams p;
    p.sheet.size = {0.4, 0.4};
    p.sheet.dx = 0.02;
    p.sheet.center = {0.0, 0.0, 0.2};
    p.material.youngsModulus = 1e5;
    p.material.density = 1000;
    p.gravity = {0.0, 0.0, -9.81};
    p.damping = 1.0;
    p.contact.ground = {true, -0.1, {0.5, 0.5}};
    p.contact.self.enabled = true;
    sim::ColliderParams ball;
    ball.radius = 0.14;
    ball.position = {0.0, 0.0, 0.04};  // on the ground, its lower half bare
    p.contact.colliders.push_back(ball);
    sim::Membrane m(p);
    m.advanceTo(0.5);
    return m;
}

}  // namespace

TEST(RenderRegression, AFrameWithContactMatchesItsReference) {
    const sim::Membrane m = drapedSheet();
    const sim::FrameView frame = m.view(1);
    render::RenderSettings settings = frameSettings();
    settings.colorBy = render::ColorBy::None;
    settings.camera.position = Eigen::Vector3d(0.3, -0.55, 0.35);
    settings.camera.lookAt = Eigen::Vector3d(0.0, 0.0, 0.02);
    settings.colliderLooks = {render::ColliderLook{{0.7, 0.15, 0.1}, 0.5, false}};
    const render::Mesh mesh = render::LatticeSurface(frame).build(frame, settings);
    const std::vector<render::Mesh> colliders = render::colliderMeshes(frame);
    ASSERT_EQ(colliders.size(), 1u);
    const render::Image image = render::OsmesaRenderer().render(mesh, settings, colliders);
    const render::Image sheetOnly = render::OsmesaRenderer().render(mesh, settings);
    EXPECT_GT(rend::test::pixelsDiffering(image, sheetOnly, 8), 100) << "the ball shows";
    double lowest = 1e300;
    for (const Eigen::Vector3d& x : m.positions()) lowest = std::min(lowest, x.z());
    EXPECT_GE(lowest, -0.1) << "nothing below the ground";
    rend::test::expectMatchesReference(image, "regress_osmesa_contact");
}
