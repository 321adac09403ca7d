// Tests for the Embree path tracer: framing, determinism across thread counts, BVH refit,
// materials, and two reference images (a foil mesh and translucent splats).

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include "TestSupport.h"
#include "render/EmbreeRenderer.h"
#include "render/Image.h"

using rend::render::EmbreeRenderer;
using rend::render::Geometry;
using rend::render::Image;
using rend::render::MaterialKind;
using rend::render::Mesh;
using rend::render::RenderSettings;
using rend::render::Splats;
using rend::test::expectMatchesReference;
using rend::test::pixel;
using rend::test::pixelDistance;
using rend::test::pixelsUnlike;

namespace {

// A 2.3 x 1.5 sheet centred on the origin: a standing wave along x (as in render_test.cpp's
// OSMesa fixture) plus a finer oblique ripple, so a metal sheet shows crinkle highlights.
// Built by hand so these tests pin down the renderer alone.
constexpr int kNx = 47;
constexpr int kNy = 31;
constexpr double kDx = 0.05;

double height(double x, double y, double phase) {
    const double tau = 2.0 * std::numbers::pi;
    return 0.15 * std::sin(tau * x / 1.2 + phase) + 0.025 * std::sin(tau * (0.8 * x + y) / 0.45);
}

Eigen::Vector3f point(int i, int j, double phase) {
    const double x = (i - 0.5 * (kNx - 1)) * kDx;
    const double y = (j - 0.5 * (kNy - 1)) * kDx;
    return Eigen::Vector3d(x, y, height(x, y, phase)).cast<float>();
}

// The surface normal from the height field's central-difference gradient.
Eigen::Vector3f normal(const Eigen::Vector3f& p, double phase) {
    const double h = 1e-4;
    const double gx = (height(p.x() + h, p.y(), phase) - height(p.x() - h, p.y(), phase)) / (2 * h);
    const double gy = (height(p.x(), p.y() + h, phase) - height(p.x(), p.y() - h, phase)) / (2 * h);
    return Eigen::Vector3d(-gx, -gy, 1.0).normalized().cast<float>();
}

Mesh wavyMesh(double phase = 0.0, Eigen::Vector3f color = Eigen::Vector3f(0.8f, 0.8f, 0.8f)) {
    return rend::test::gridMesh(kNx, kNy, [&](int i, int j) {
        const Eigen::Vector3f p = point(i, j, phase);
        return rend::test::GridVertex{p, normal(p, phase), color};
    });
}

// One disc per grid point. A radius of 0.8 dx exceeds half the cell diagonal (0.71 dx), so
// the discs close every gap of the square grid.
Splats wavySplats(double phase = 0.0) {
    Splats splats;
    for (int j = 0; j < kNy; ++j) {
        for (int i = 0; i < kNx; ++i) {
            splats.centers.push_back(point(i, j, phase));
            splats.normals.push_back(normal(splats.centers.back(), phase));
            // A seaweed-like green that brightens along x, to show per-disc colour.
            splats.colors.emplace_back(0.25f, 0.45f + 0.25f * float(i) / kNx, 0.2f);
            splats.radii.push_back(float(0.8 * kDx));
        }
    }
    return splats;
}

RenderSettings smallSettings(MaterialKind material = MaterialKind::Diffuse) {
    RenderSettings settings;
    settings.width = 160;
    settings.height = 90;
    settings.camera.position = Eigen::Vector3d(0.6, -3.0, 1.0);
    settings.camera.lookAt = Eigen::Vector3d(0.0, 0.0, -0.1);
    // Behind the sheet and above: the crinkles then mirror it towards the camera.
    settings.sun.direction = Eigen::Vector3d(-0.3, 1.0, 0.8);
    settings.pathTracing.samplesPerPixel = 16;
    settings.pathTracing.maxDepth = 3;
    settings.pathTracing.material = material;
    return settings;
}

double meanAbsDifference(const Image& a, const Image& b) {
    double sum = 0.0;
    for (std::size_t k = 0; k < a.rgb.size(); ++k) sum += std::abs(int(a.rgb[k]) - int(b.rgb[k]));
    return sum / double(a.rgb.size());
}

// Rec. 709 luma of the encoded pixel, 0..255.
double maxLuma(const Image& image) {
    double best = 0.0;
    for (std::size_t k = 0; k < image.rgb.size(); k += 3)
        best = std::max(
            best, 0.2126 * image.rgb[k] + 0.7152 * image.rgb[k + 1] + 0.0722 * image.rgb[k + 2]);
    return best;
}

Image renderOnce(const Geometry& geometry, const RenderSettings& settings) {
    EmbreeRenderer renderer;
    return renderer.render(geometry, settings);
}

/// Runs `body` with `threads` OpenMP threads and restores the previous setting.
template <class F>
Image withThreads(int threads, F body) {
    const int previous = omp_get_max_threads();
    omp_set_num_threads(threads);
    Image image = body();
    omp_set_num_threads(previous);
    return image;
}

}  // namespace

TEST(EmbreeRenderer, DescribesTheLoadedEmbree) {
    EmbreeRenderer renderer;
    const std::string description = renderer.deviceDescription();
    std::cout << "  " << description << "\n";
    EXPECT_EQ(description.rfind("Embree 3.", 0), 0u) << description;
}

TEST(EmbreeRenderer, SheetIsVisibleAsMeshAndAsSplats) {
    RenderSettings settings = smallSettings();
    settings.ground = false;
    settings.pathTracing.sky = false;  // a constant background: the corner pixel is exact
    settings.pathTracing.samplesPerPixel = 4;
    const Mesh terracotta = wavyMesh(0.0, Eigen::Vector3f(0.7f, 0.3f, 0.2f));
    for (const Geometry& geometry : {Geometry(terracotta), Geometry(wavySplats())}) {
        EmbreeRenderer renderer;
        const Image image = renderer.render(geometry, settings);
        ASSERT_EQ(image.width, 160);
        ASSERT_EQ(image.height, 90);
        ASSERT_EQ(image.rgb.size(), 160u * 90u * 3u);
        EXPECT_GT(renderer.raysTraced(), 160LL * 90 * 4);
        const std::uint8_t* corner = pixel(image, 0, 0);
        EXPECT_GT(pixelDistance(pixel(image, 80, 45), corner), 30);
        EXPECT_GT(pixelsUnlike(image, corner, 8), image.width * image.height / 10);
    }
}

TEST(EmbreeRenderer, EmptyGeometryRendersOnlyGroundAndSky) {
    RenderSettings settings = smallSettings();
    settings.pathTracing.samplesPerPixel = 2;
    EmbreeRenderer renderer;
    const Image withGround = renderer.render(Mesh{}, settings);
    settings.ground = false;
    const Image skyOnly = renderer.render(Mesh{}, settings);
    // The camera looks down from above the ground: its lower half is ground.
    EXPECT_GT(pixelDistance(pixel(withGround, 80, 89), pixel(skyOnly, 80, 89)), 10);
    settings.pathTracing.sky = false;
    const Image background = renderer.render(Splats{}, settings);
    for (int y = 0; y < background.height; ++y)
        for (int x = 0; x < background.width; ++x)
            ASSERT_EQ(pixelDistance(pixel(background, x, y), pixel(background, 0, 0)), 0);
}

TEST(EmbreeRenderer, OneAndTwoThreadsGiveIdenticalBytes) {
    RenderSettings settings = smallSettings(MaterialKind::Film);
    settings.pathTracing.transmission = 0.5;
    settings.pathTracing.samplesPerPixel = 4;
    for (const Geometry& geometry : {Geometry(wavyMesh()), Geometry(wavySplats())}) {
        const Image one = withThreads(1, [&] { return renderOnce(geometry, settings); });
        const Image two = withThreads(2, [&] { return renderOnce(geometry, settings); });
        EXPECT_EQ(one.rgb, two.rgb);
    }
}

TEST(EmbreeRenderer, RefitGivesTheSameImageAsAFreshBuild) {
    RenderSettings settings = smallSettings(MaterialKind::Conductor);
    settings.pathTracing.samplesPerPixel = 4;
    const std::vector<std::pair<Geometry, Geometry>> frames = {{wavyMesh(0.0), wavyMesh(0.9)},
                                                               {wavySplats(0.0), wavySplats(0.9)}};
    for (const auto& [first, second] : frames) {
        EmbreeRenderer reused;
        const Image before = reused.render(first, settings);
        const Image refitted = reused.render(second, settings);  // same topology: refit
        const Image fresh = renderOnce(second, settings);
        EXPECT_EQ(refitted.rgb, fresh.rgb);
        EXPECT_GT(meanAbsDifference(before, refitted), 1.0);  // the refit did move the sheet
    }
}

TEST(EmbreeRenderer, ChangedTopologyRebuilds) {
    RenderSettings settings = smallSettings();
    settings.pathTracing.samplesPerPixel = 2;
    Mesh torn = wavyMesh();
    torn.triangles.resize(torn.triangles.size() / 2);  // drop the far half of the sheet
    EmbreeRenderer renderer;
    renderer.render(wavyMesh(), settings);
    renderer.render(wavySplats(), settings);
    EXPECT_EQ(renderer.render(torn, settings).rgb, renderOnce(torn, settings).rgb);
}

TEST(EmbreeRenderer, ConductorReadsAsMetalNotAsDiffuse) {
    // Mid-grey, so the brightest diffuse pixel stays below white and a highlight can exceed it.
    // A dark, constant surrounding leaves the sheet the brightest thing in the frame.
    const Mesh mesh = wavyMesh(0.0, Eigen::Vector3f(0.5f, 0.5f, 0.5f));
    RenderSettings settings = smallSettings(MaterialKind::Diffuse);
    settings.ground = false;
    settings.pathTracing.sky = false;
    settings.background = Eigen::Vector3d(0.1, 0.1, 0.1);
    const Image diffuse = renderOnce(mesh, settings);
    settings.pathTracing.material = MaterialKind::Conductor;
    const Image metal = renderOnce(mesh, settings);
    EXPECT_GT(meanAbsDifference(diffuse, metal), 4.0);
    EXPECT_GT(maxLuma(metal), maxLuma(diffuse) + 10.0);  // sun highlights on the crinkles
}

TEST(EmbreeRenderer, DenoisedFourSamplesAreCloserToTheReferenceThanSixteen) {
    // The translucent sheet over the ground: noise in the sheet and in its shadow.
    RenderSettings settings = smallSettings(MaterialKind::Translucent);
    settings.pathTracing.transmission = 0.3;
    settings.pathTracing.seed = 1;
    settings.pathTracing.samplesPerPixel = 256;
    const Image reference = renderOnce(wavyMesh(), settings);
    settings.pathTracing.seed = 0;
    settings.pathTracing.samplesPerPixel = 16;
    const Image sixteen = renderOnce(wavyMesh(), settings);
    settings.pathTracing.samplesPerPixel = 4;
    const Image four = renderOnce(wavyMesh(), settings);
    settings.pathTracing.denoise = true;
    const Image denoised = withThreads(1, [&] { return renderOnce(wavyMesh(), settings); });
    EXPECT_LT(meanAbsDifference(denoised, reference), meanAbsDifference(sixteen, reference));
    EXPECT_LT(meanAbsDifference(denoised, reference), 0.5 * meanAbsDifference(four, reference));
    EXPECT_EQ(withThreads(2, [&] { return renderOnce(wavyMesh(), settings); }).rgb, denoised.rgb);
}

TEST(EmbreeRenderer, AMirrorShowsTheSunAtFourSamplesAsAtTwoHundredFiftySix) {
    // A flat near-mirror (GGX alpha 1e-3, far narrower than the sun's 2-degree cone) seen at the
    // sun's mirror angle. Cone samples alone almost never land in such a lobe; the BSDF's own
    // samples, weighted against them (MIS), hit the sun at once.
    const Mesh mirror = rend::test::gridMesh(21, 21, [](int i, int j) {
        const Eigen::Vector3f p(0.1f * float(i - 10), 0.1f * float(j - 10), 0.0f);
        return rend::test::GridVertex{p, Eigen::Vector3f::UnitZ(), Eigen::Vector3f::Constant(0.9f)};
    });
    RenderSettings settings = smallSettings(MaterialKind::Conductor);
    settings.pathTracing.roughness = 0.01;
    settings.pathTracing.sky = false;
    settings.ground = false;
    settings.background = Eigen::Vector3d::Zero();
    settings.camera.position = Eigen::Vector3d(0.0, -3.0, 3.0);
    settings.camera.lookAt = Eigen::Vector3d::Zero();
    settings.sun.direction = Eigen::Vector3d(0.0, 1.0, 1.0);
    settings.sun.intensity = 5e-4;  // the reflected sun at about half of display white
    settings.tone.curve = rend::render::ToneCurve::Clamp;
    settings.pathTracing.samplesPerPixel = 256;
    const Image reference = renderOnce(mirror, settings);
    settings.pathTracing.samplesPerPixel = 4;
    const Image four = renderOnce(mirror, settings);
    // The sun's disc, about 10 pixels across at the frame's centre: its central 6 x 6 pixels.
    double glint = 0.0, difference = 0.0;
    for (int y = 42; y < 48; ++y)
        for (int x = 77; x < 83; ++x) {
            glint += pixel(reference, x, y)[1];
            difference += std::abs(int(pixel(four, x, y)[1]) - int(pixel(reference, x, y)[1]));
        }
    EXPECT_GT(glint / 36.0, 100.0) << "the sun's reflection is in the frame";
    EXPECT_LT(difference, 0.1 * glint);
}

TEST(EmbreeRenderer, EveryPixelConvergesToTheSameImageWhateverTheSeed) {
    // Two seeds' images differ by v/N + v/M in mean square when each pixel's estimate converges
    // to the integral: from 4 to 64 samples against a 256-sample reference of another seed the
    // RMS difference falls 3.6-fold for independent samples, more with stratification (3.9).
    // When the path's random numbers are fixed functions of one another (a digit XOR on the
    // sample index did that), each pixel converges to a value of its own and the difference
    // stalls: 2.6-fold here, 1.4-fold on the torn foil from 16 to 256 samples.
    RenderSettings settings = smallSettings(MaterialKind::Conductor);
    settings.pathTracing.roughness = 0.3;  // glossy: sun cone, lobe choice and shape all count
    const auto linear = [&](int spp, int seed) {
        settings.pathTracing.samplesPerPixel = spp;
        settings.pathTracing.seed = seed;
        rend::render::FrameLayers layers;
        EmbreeRenderer renderer;
        (void)renderer.render(wavyMesh(), settings, &layers);
        return layers.rgb;
    };
    const std::vector<float> reference = linear(256, 1);
    const auto rms = [&](const std::vector<float>& image) {
        double sum = 0.0;
        for (std::size_t k = 0; k < image.size(); ++k) {
            const double d = std::min(image[k], 1.0f) - std::min(reference[k], 1.0f);
            sum += d * d;
        }
        return std::sqrt(sum / double(image.size()));
    };
    const double four = rms(linear(4, 0)), sixtyFour = rms(linear(64, 0));
    EXPECT_GT(four / sixtyFour, 3.0) << "4 spp " << four << ", 64 spp " << sixtyFour;
}

TEST(EmbreeRenderer, RejectsInconsistentGeometry) {
    EmbreeRenderer renderer;
    Mesh mesh = wavyMesh();
    mesh.normals.pop_back();
    EXPECT_THROW(renderer.render(mesh, smallSettings()), std::invalid_argument);
    mesh = wavyMesh();
    mesh.triangles.push_back({0, 1, 999999});
    EXPECT_THROW(renderer.render(mesh, smallSettings()), std::invalid_argument);
    Splats splats = wavySplats();
    splats.radii.pop_back();
    EXPECT_THROW(renderer.render(splats, smallSettings()), std::invalid_argument);
    RenderSettings settings = smallSettings();
    settings.width = 0;
    EXPECT_THROW(renderer.render(wavyMesh(), settings), std::invalid_argument);
}

TEST(EmbreeRenderer, MatchesTheFoilReferenceImage) {
    expectMatchesReference(renderOnce(wavyMesh(), smallSettings(MaterialKind::Conductor)),
                           "embree_sheet");
}

TEST(EmbreeRenderer, MatchesTheTranslucentSplatsReferenceImage) {
    RenderSettings settings = smallSettings(MaterialKind::Translucent);
    settings.pathTracing.transmission = 0.4;
    expectMatchesReference(renderOnce(wavySplats(), settings), "embree_splats");
}
