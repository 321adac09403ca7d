// The path tracer's linear output and first-hit layers (the EXR frame), the sky control variate
// on the ground plane, and the EXR file itself (render/ExrWriter.h).

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>

#include "render/EmbreeRenderer.h"
#include "render/ExrWriter.h"
#include "tests/ScratchDir.h"

using rend::render::EmbreeRenderer;
using rend::render::FrameLayers;
using rend::render::Mesh;
using rend::render::RenderSettings;

namespace {

// Odd, so the middle pixel's centre ray is the camera's axis.
constexpr int kSize = 33;
constexpr int kMiddle = kSize / 2;

/// Looking straight down from `height` above the ground plane at z = 0.
RenderSettings lookingDown(double height) {
    RenderSettings settings;
    settings.width = settings.height = kSize;
    settings.camera.position = Eigen::Vector3d(0.0, 0.0, height);
    settings.camera.lookAt = Eigen::Vector3d(0.0, 0.0, 0.0);
    settings.camera.up = Eigen::Vector3d(0.0, 1.0, 0.0);
    settings.ground = true;
    settings.groundHeight = 0.0;
    settings.pathTracing.samplesPerPixel = 16;
    return settings;
}

/// A square of side `size` at height z, two triangles, colour `albedo`.
Mesh square(double size, double z, float albedo) {
    Mesh mesh;
    const float h = float(size / 2);
    for (const auto& [x, y] : {std::pair{-h, -h}, {h, -h}, {h, h}, {-h, h}}) {
        mesh.positions.emplace_back(x, y, float(z));
        mesh.normals.emplace_back(0.0f, 0.0f, 1.0f);
        mesh.colors.emplace_back(albedo, albedo, albedo);
    }
    mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
    return mesh;
}

Eigen::Vector3f linearAt(const FrameLayers& layers, int x, int y) {
    const std::size_t i = 3 * (std::size_t(y) * layers.width + x);
    return {layers.rgb[i], layers.rgb[i + 1], layers.rgb[i + 2]};
}

}  // namespace

TEST(EmbreeLayers, OpenGroundIsExactlyTheSunPlusTheSkysCosineWeightedMean) {
    // Lambert ground under a sun cone of radius r and the zenith-to-horizon gradient:
    // L = albedo (intensity s_z (1 + cos r) / 2 + h + 2/3 (z - h)). The control variate makes
    // the sky term exact; only the sun cone's cosine varies, by far less than the tolerance.
    RenderSettings settings = lookingDown(2.0);
    EmbreeRenderer renderer;
    FrameLayers layers;
    renderer.render(Mesh{}, settings, &layers);
    const Eigen::Vector3d s = settings.sun.direction.normalized();
    const double cone =
        (1.0 + std::cos(settings.pathTracing.sunAngularRadiusDegrees * std::numbers::pi / 180.0)) /
        2.0;
    const auto& pt = settings.pathTracing;
    for (int k = 0; k < 3; ++k) {
        const double sky = pt.skyHorizon[k] + (pt.skyZenith[k] - pt.skyHorizon[k]) * 2.0 / 3.0;
        const double expected =
            settings.groundColor[k] * (settings.sun.intensity * s.z() * cone + sky);
        EXPECT_NEAR(linearAt(layers, kMiddle, kMiddle)[k], expected, 1e-3 * expected) << k;
    }
}

TEST(EmbreeLayers, GroundUnderABlackRoofSeesNoSkyDespiteTheControlVariate) {
    // A black roof 0.5 m above the ground, 40 m wide, the camera between the two: the ground
    // sees almost only the roof, so its sky light must come out near zero. Were the variate's
    // correction missing when a bounce hits the roof, the ground would show the full sky mean.
    RenderSettings settings = lookingDown(0.25);
    settings.sun.intensity = 0.0;
    EmbreeRenderer renderer;
    FrameLayers layers;
    renderer.render(square(40.0, 0.5, 0.0f), settings, &layers);
    const Eigen::Vector3f ground = linearAt(layers, kMiddle, kMiddle);
    const double openSky = settings.groundColor.x() * settings.pathTracing.skyHorizon.x();
    EXPECT_LT(ground.maxCoeff(), 0.02 * openSky);
    EXPECT_GT(ground.minCoeff(), -0.02 * openSky);
}

TEST(EmbreeLayers, LinearLayerMatchesThePngBeforeEncoding) {
    RenderSettings settings = lookingDown(2.0);
    settings.pathTracing.samplesPerPixel = 4;
    EmbreeRenderer renderer;
    FrameLayers layers;
    const auto image = renderer.render(square(1.0, 0.3, 0.7f), settings, &layers);
    ASSERT_EQ(layers.width, kSize);
    ASSERT_EQ(layers.rgb.size(), std::size_t(kSize) * kSize * 3);
    // The same render without layers gives the same bytes: the layers cost nothing to the PNG.
    EXPECT_EQ(renderer.render(square(1.0, 0.3, 0.7f), settings).rgb, image.rgb);
}

TEST(EmbreeLayers, DepthAndNormalAreThoseOfTheFirstHitAlongThePixelCentre) {
    RenderSettings settings = lookingDown(2.0);
    settings.ground = false;
    settings.pathTracing.samplesPerPixel = 1;
    EmbreeRenderer renderer;
    FrameLayers layers;
    renderer.render(square(0.5, 0.3, 0.7f), settings, &layers);
    const std::size_t middle = std::size_t(kMiddle) * kSize + kMiddle;
    EXPECT_NEAR(layers.depth[middle], 1.7f, 1e-4f);
    EXPECT_NEAR(layers.normal[3 * middle + 2], 1.0f, 1e-5f);  // faces the camera, world +z
    EXPECT_EQ(layers.depth[0], FrameLayers::kNoHit);          // the corner misses the square
    EXPECT_EQ(layers.normal[0], 0.0f);
    EXPECT_TRUE(layers.theta.empty()) << "a mesh without theta has no theta layer";
}

TEST(EmbreeLayers, ThetaIsInterpolatedAtTheFirstHit) {
    RenderSettings settings = lookingDown(2.0);
    settings.pathTracing.samplesPerPixel = 1;
    Mesh mesh = square(0.5, 0.3, 0.7f);
    // Corners (-, -), (+, -), (+, +), (-, +): theta = 1 + x + y at the corners, linear inside.
    mesh.theta = {0.5f, 1.0f, 1.5f, 1.0f};
    EmbreeRenderer renderer;
    FrameLayers layers;
    renderer.render(mesh, settings, &layers);
    ASSERT_EQ(layers.theta.size(), std::size_t(kSize) * kSize);
    EXPECT_NEAR(layers.theta[std::size_t(kMiddle) * kSize + kMiddle], 1.0f, 1e-4f);
    EXPECT_EQ(layers.theta[0], 0.0f);  // the ground
}

TEST(ExrWriter, WritesAndReadsBackEveryChannelWithItsValues) {
    FrameLayers layers;
    layers.width = 5;
    layers.height = 3;
    for (int i = 0; i < 15; ++i) {
        for (float v : {0.25f * i, 0.5f, 2.0f}) layers.rgb.push_back(v);
        layers.depth.push_back(1.0f + 0.001f * float(i));
        for (float v : {0.0f, 0.6f, 0.8f}) layers.normal.push_back(v);
    }
    const auto path = rend::test::scratchDir() / "layers.exr";
    rend::render::writeExrAtomic(layers, path);
    EXPECT_FALSE(std::filesystem::exists(path.string() + ".tmp"));
    const rend::render::ExrChannels read = rend::render::readExr(path);
    EXPECT_EQ(read.width, 5);
    EXPECT_EQ(read.height, 3);
    std::vector<std::string> names;
    for (const auto& [name, values] : read.channels) names.push_back(name);
    EXPECT_EQ(names, (std::vector<std::string>{"B", "G", "N.X", "N.Y", "N.Z", "R", "Z"}));
    // Pixel (2, 1) is number 7: R 1.75 and the halves' 11-bit precision; Z in full float.
    EXPECT_FLOAT_EQ(read.channels.at("R")[7], 1.75f);
    EXPECT_FLOAT_EQ(read.channels.at("B")[7], 2.0f);
    EXPECT_NEAR(read.channels.at("N.Y")[7], 0.6f, 1e-3f);
    EXPECT_FLOAT_EQ(read.channels.at("Z")[7], 1.007f);
    std::filesystem::remove(path);
}

TEST(ExrWriter, RefusesALayerOfTheWrongSize) {
    FrameLayers layers;
    layers.width = 4;
    layers.height = 4;
    layers.rgb.assign(4 * 4 * 3, 0.0f);
    layers.depth.assign(5, 0.0f);
    EXPECT_THROW(rend::render::writeExrAtomic(layers, "unused.exr"), std::invalid_argument);
}

TEST(EmbreeLayers, AnotherSeedGivesOtherNoiseAroundTheSameMean) {
    RenderSettings settings = lookingDown(2.0);
    settings.sun.direction = Eigen::Vector3d(-0.3, 0.2, 1.0);  // the square's shadow is in view
    settings.pathTracing.samplesPerPixel = 8;
    const Mesh mesh = square(1.0, 0.4, 0.7f);
    EmbreeRenderer renderer;
    FrameLayers first, second;
    renderer.render(mesh, settings, &first);
    settings.pathTracing.seed = 1;
    renderer.render(mesh, settings, &second);
    double meanFirst = 0.0, meanSecond = 0.0;
    std::size_t differ = 0;
    for (std::size_t i = 0; i < first.rgb.size(); ++i) {
        meanFirst += first.rgb[i] / double(first.rgb.size());
        meanSecond += second.rgb[i] / double(first.rgb.size());
        differ += first.rgb[i] != second.rgb[i];
    }
    EXPECT_GT(differ, first.rgb.size() / 10);
    EXPECT_NEAR(meanFirst, meanSecond, 0.01 * meanFirst);
}
