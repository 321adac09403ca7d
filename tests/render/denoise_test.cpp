// Tests for the a-trous denoiser (render/Denoise.h) on synthetic frames whose true image is
// known: it removes noise on a surface, keeps a silhouette and an albedo texture sharp, leaves a
// noise-free image alone, and gives the same bits for any thread count.

#include "render/Denoise.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <stdexcept>
#include <vector>

#include "render/ExrWriter.h"

using rend::render::denoise;
using rend::render::DenoiseGuides;
using rend::render::FrameLayers;

namespace {

constexpr int kWidth = 96;
constexpr int kHeight = 64;
constexpr float kNoise = 0.1f;  // standard deviation of each pixel's mean

/// A frame: the true linear image, a noisy copy, and the guides.
struct Frame {
    std::vector<float> truth;
    std::vector<float> noisy;
    DenoiseGuides guides{kWidth, kHeight, {}, {}, {}, {}};
};

/// A flat surface facing the camera at depth 2, lit by `light`, with albedo `albedo(x, y)`; the
/// columns from `skyFrom` on are sky of radiance `sky` (no hit, no noise).
template <class Albedo>
Frame makeFrame(float light, Albedo albedo, int skyFrom = kWidth, float sky = 0.9f) {
    Frame f;
    std::mt19937 rng(7);
    std::normal_distribution<float> gauss(0.0f, kNoise);
    for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
            const bool isSky = x >= skyFrom;
            const float a = isSky ? 1.0f : albedo(x, y);
            const float value = isSky ? sky : light * a;
            const float n = isSky ? 0.0f : gauss(rng) * a;
            for (int k = 0; k < 3; ++k) {
                f.truth.push_back(value);
                f.noisy.push_back(value + n);
                f.guides.albedo.push_back(a);
                f.guides.normal.push_back(isSky || k < 2 ? 0.0f : 1.0f);
            }
            f.guides.depth.push_back(isSky ? FrameLayers::kNoHit : 2.0f);
            f.guides.variance.push_back(isSky ? 0.0f : kNoise * kNoise * a * a);
        }
    }
    return f;
}

double rmse(const std::vector<float>& a, const std::vector<float>& b) {
    double sum = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) sum += double(a[i] - b[i]) * double(a[i] - b[i]);
    return std::sqrt(sum / double(a.size()));
}

float at(const std::vector<float>& rgb, int x, int y) { return rgb[3 * (y * kWidth + x)]; }

}  // namespace

TEST(Denoise, RemovesMostOfTheNoiseOnAFlatSurface) {
    Frame f = makeFrame(0.5f, [](int, int) { return 0.8f; });
    const double before = rmse(f.noisy, f.truth);
    denoise(f.noisy, f.guides);
    EXPECT_LT(rmse(f.noisy, f.truth), 0.2 * before);
}

TEST(Denoise, KeepsASilhouetteSharp) {
    Frame f = makeFrame(
        0.25f, [](int, int) { return 0.8f; }, kWidth / 2);
    denoise(f.noisy, f.guides);
    for (int y = 0; y < kHeight; ++y) {
        // The sky keeps its exact value; the surface next to it gets none of the sky's light.
        EXPECT_FLOAT_EQ(at(f.noisy, kWidth / 2, y), 0.9f);
        EXPECT_NEAR(at(f.noisy, kWidth / 2 - 1, y), 0.2f, 0.06f) << "row " << y;
    }
}

TEST(Denoise, KeepsTheAlbedoTextureWhileRemovingNoise) {
    // A checkerboard of 2-pixel squares: a filter of the colour itself would blur it to grey.
    const auto checker = [](int x, int y) { return ((x / 2 + y / 2) % 2) ? 0.9f : 0.3f; };
    Frame f = makeFrame(0.6f, checker);
    const double before = rmse(f.noisy, f.truth);
    denoise(f.noisy, f.guides);
    EXPECT_LT(rmse(f.noisy, f.truth), 0.3 * before);
    EXPECT_NEAR(at(f.noisy, 10, 10), 0.6f * checker(10, 10), 0.04f);
    EXPECT_NEAR(at(f.noisy, 12, 10), 0.6f * checker(12, 10), 0.04f);
}

TEST(Denoise, LeavesANoiseFreeImageAsItIs) {
    Frame f = makeFrame(
        0.5f, [](int x, int) { return 0.2f + 0.006f * float(x); }, 70);
    std::fill(f.guides.variance.begin(), f.guides.variance.end(), 0.0f);
    std::vector<float> image = f.truth;
    denoise(image, f.guides);
    for (std::size_t i = 0; i < image.size(); ++i) ASSERT_NEAR(image[i], f.truth[i], 1e-6f);
}

TEST(Denoise, EstimatesTheNoiseOfOneSampleFromTheNeighbours) {
    Frame f = makeFrame(
        0.5f, [](int, int) { return 0.8f; }, 80);
    f.guides.variance.clear();
    const double before = rmse(f.noisy, f.truth);
    denoise(f.noisy, f.guides);
    EXPECT_LT(rmse(f.noisy, f.truth), 0.3 * before);
    EXPECT_FLOAT_EQ(at(f.noisy, 85, 5), 0.9f);
}

TEST(Denoise, OneAndTwoThreadsGiveIdenticalBits) {
    const Frame f = makeFrame(
        0.4f, [](int x, int y) { return ((x + y) % 5) ? 0.7f : 0.4f; }, 60);
    std::vector<float> one = f.noisy, two = f.noisy;
    const int previous = omp_get_max_threads();
    omp_set_num_threads(1);
    denoise(one, f.guides);
    omp_set_num_threads(2);
    denoise(two, f.guides);
    omp_set_num_threads(previous);
    EXPECT_EQ(one, two);
}

TEST(Denoise, RefusesGuidesOfAnotherSize) {
    Frame f = makeFrame(0.5f, [](int, int) { return 0.8f; });
    f.guides.depth.pop_back();
    EXPECT_THROW(denoise(f.noisy, f.guides), std::invalid_argument);
}
