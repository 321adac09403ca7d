#include "render/Denoise.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include "render/ExrWriter.h"

namespace rend::render {

namespace {

// SVGF's edge-stopping parameters: sigma_l scales the luminance noise, sigma_n is the power on
// the normals' cosine, sigma_z scales the depth's own slope.
constexpr float kSigmaLuminance = 4.0f;
constexpr int kNormalSquarings = 7;  // cos^128
constexpr float kSigmaDepth = 1.0f;
// A depth step below this fraction of the depth is the same surface, whatever its slope.
constexpr float kDepthTolerance = 2e-3f;
// The light under a black surface is unknown: demodulate by at least this albedo.
constexpr float kMinAlbedo = 0.02f;
constexpr std::array<float, 3> kKernel{0.25f, 0.5f, 0.25f};  // B-spline, per axis

float luminance(const float* c) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }

/// e^-x for x >= 0 to about 1e-4 relative: an edge-stopping weight needs no more, and the
/// library's expf was a quarter of the filter's time. 2^t = 2^floor(t) (the exponent bits)
/// x a cubic for 2^frac(t) on [0, 1).
float expNegative(float x) {
    const float t = -std::min(x, 80.0f) * 1.44269504f;  // log2(e)
    const float whole = std::floor(t);
    const float f = t - whole;
    const float p = 1.0f + f * (0.69583356f + f * (0.22606716f + f * 0.07944023f));
    return p * std::bit_cast<float>(std::uint32_t(int(whole) + 127) << 23);
}

bool hasHit(float depth) { return depth < FrameLayers::kNoHit; }

/// All a tap reads of one pixel, side by side (one cache line), so the wide taps of the late
/// passes cost one miss each.
struct Texel {
    std::array<float, 3> light{};  ///< radiance over albedo
    float luminance = 0.0f;
    float variance = 0.0f;  ///< of the light's luminance
    float depth = FrameLayers::kNoHit;
    std::array<float, 3> normal{};
    std::array<float, 2> slope{};  ///< d depth / d pixel along x and y
    float pad = 0.0f;
};

struct Image {
    int width = 0, height = 0;
    std::vector<Texel> texels;

    Texel& at(int x, int y) { return texels[std::size_t(y) * width + x]; }
    const Texel& at(int x, int y) const { return texels[std::size_t(y) * width + x]; }
    bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < width && y < height; }
};

/// The depth's slope at (x, y) along (dx, dy): the smaller one-sided difference, so a
/// silhouette next to the pixel does not pass for a steep surface.
float depthSlope(const Image& im, int x, int y, int dx, int dy) {
    const float z = im.at(x, y).depth;
    float best = std::numeric_limits<float>::infinity();
    for (const int s : {-1, 1}) {
        const int qx = x + s * dx, qy = y + s * dy;
        if (!im.inside(qx, qy) || !hasHit(z) || !hasHit(im.at(qx, qy).depth)) continue;
        best = std::min(best, std::abs(im.at(qx, qy).depth - z));
    }
    return std::isfinite(best) ? best : 0.0f;
}

/// The light a pixel receives: its radiance over the first hit's albedo (so the surface's own
/// texture is not blurred), with the variance of its luminance, and the geometry.
void demodulate(const std::vector<float>& rgb, const DenoiseGuides& g, Image& im) {
    im.width = g.width;
    im.height = g.height;
    im.texels.resize(rgb.size() / 3);
    const auto n = std::ptrdiff_t(im.texels.size());
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t p = 0; p < n; ++p) {
        Texel& t = im.texels[p];
        std::array<float, 3> a;
        for (int k = 0; k < 3; ++k) {
            a[k] = std::max(g.albedo[3 * p + k], kMinAlbedo);
            t.light[k] = rgb[3 * p + k] / a[k];
            t.normal[k] = g.normal[3 * p + k];
        }
        t.luminance = luminance(t.light.data());
        const float l = luminance(a.data());
        t.variance = g.variance.empty() ? 0.0f : g.variance[p] / (l * l);
        t.depth = g.depth[p];
    }
#pragma omp parallel for schedule(static)
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x)
            im.at(x, y).slope = {depthSlope(im, x, y, 1, 0), depthSlope(im, x, y, 0, 1)};
}

void remodulate(const Image& im, const DenoiseGuides& g, std::vector<float>& rgb) {
    const auto n = std::ptrdiff_t(im.texels.size());
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t p = 0; p < n; ++p)
        for (int k = 0; k < 3; ++k)
            rgb[3 * p + k] = im.texels[p].light[k] * std::max(g.albedo[3 * p + k], kMinAlbedo);
}

/// Normal and depth weight of tap q at pixel offset (ox, oy) from p (0 across a silhouette);
/// `depthTerm` is the depth's share of the weight's exponent.
float geometryWeight(const Texel& p, const Texel& q, int ox, int oy, float& depthTerm) {
    depthTerm = 0.0f;
    if (!hasHit(p.depth) || !hasHit(q.depth)) return hasHit(p.depth) == hasHit(q.depth);
    float c = std::max(
        0.0f, p.normal[0] * q.normal[0] + p.normal[1] * q.normal[1] + p.normal[2] * q.normal[2]);
    for (int k = 0; k < kNormalSquarings; ++k) c *= c;
    const float expected = std::abs(p.slope[0] * float(ox)) + std::abs(p.slope[1] * float(oy));
    depthTerm = std::abs(p.depth - q.depth) / (kSigmaDepth * expected + kDepthTolerance * p.depth);
    return c;
}

/// SVGF's 3 x 3 Gaussian of the variance: one pixel's estimate from few samples is noisy.
void blurredVariance(const Image& im, std::vector<float>& out) {
    out.resize(im.texels.size());
#pragma omp parallel for schedule(static)
    for (int y = 0; y < im.height; ++y) {
        for (int x = 0; x < im.width; ++x) {
            float sum = 0.0f, weight = 0.0f;
            for (int j = -1; j <= 1; ++j)
                for (int i = -1; i <= 1; ++i) {
                    if (!im.inside(x + i, y + j)) continue;
                    const float w = kKernel[i + 1] * kKernel[j + 1];
                    sum += w * im.at(x + i, y + j).variance;
                    weight += w;
                }
            out[std::size_t(y) * im.width + x] = sum / weight;
        }
    }
}

/// Pixel (x, y) after one a-trous pass with taps `step` pixels apart: its light, luminance and
/// variance; `sigma2` is its blurred variance.
void filterTexel(const Image& im, int x, int y, int step, float sigma2, Texel& out) {
    const Texel& p = im.at(x, y);
    out = p;
    // Noise-free here and around (the sky, open ground under the sun): a tap whose light
    // differs at all would get no weight, so the pixel keeps its light.
    if (sigma2 <= 0.0f) return;
    const float inverseSigma = 1.0f / (kSigmaLuminance * std::sqrt(sigma2) + 1e-6f);
    std::array<float, 3> sum{};
    float weight = 0.0f, sumVariance = 0.0f;
    for (int j = -1; j <= 1; ++j) {
        for (int i = -1; i <= 1; ++i) {
            const int qx = x + i * step, qy = y + j * step;
            if (!im.inside(qx, qy)) continue;
            const Texel& q = im.at(qx, qy);
            float depthTerm = 0.0f;
            const float wg = geometryWeight(p, q, i * step, j * step, depthTerm);
            if (wg <= 0.0f) continue;
            const float dl = std::abs(q.luminance - p.luminance) * inverseSigma;
            const float w = kKernel[i + 1] * kKernel[j + 1] * wg * expNegative(dl + depthTerm);
            for (int k = 0; k < 3; ++k) sum[k] += w * q.light[k];
            sumVariance += w * w * q.variance;
            weight += w;
        }
    }
    // The centre tap always has weight kKernel[1]^2 > 0.
    for (int k = 0; k < 3; ++k) out.light[k] = sum[k] / weight;
    out.luminance = luminance(out.light.data());
    out.variance = sumVariance / (weight * weight);
}

void atrousPass(Image& im, Image& scratch, std::vector<float>& sigma2, int step) {
    blurredVariance(im, sigma2);
#pragma omp parallel for schedule(static)
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x)
            filterTexel(im, x, y, step, sigma2[std::size_t(y) * im.width + x], scratch.at(x, y));
    std::swap(im.texels, scratch.texels);
}

/// With one sample a pixel has no spread of its own: the spread of the light's luminance over
/// its 3 x 3 neighbours on the same side of a silhouette stands in (SVGF's spatial estimate).
void estimateVariance(Image& im, std::vector<float>& out) {
    out.resize(im.texels.size());
#pragma omp parallel for schedule(static)
    for (int y = 0; y < im.height; ++y) {
        for (int x = 0; x < im.width; ++x) {
            const bool hit = hasHit(im.at(x, y).depth);
            double sum = 0.0, squares = 0.0;
            int count = 0;
            for (int j = -1; j <= 1; ++j)
                for (int i = -1; i <= 1; ++i) {
                    if (!im.inside(x + i, y + j) || hasHit(im.at(x + i, y + j).depth) != hit)
                        continue;
                    const double l = im.at(x + i, y + j).luminance;
                    sum += l;
                    squares += l * l;
                    ++count;
                }
            const double mean = sum / count;
            out[std::size_t(y) * im.width + x] =
                float(std::max(0.0, squares / count - mean * mean));
        }
    }
    for (std::size_t p = 0; p < out.size(); ++p) im.texels[p].variance = out[p];
}

void checkSizes(const std::vector<float>& rgb, const DenoiseGuides& g) {
    const std::size_t n = std::size_t(std::max(g.width, 0)) * std::max(g.height, 0);
    if (rgb.size() != 3 * n || g.albedo.size() != 3 * n || g.normal.size() != 3 * n ||
        g.depth.size() != n || (!g.variance.empty() && g.variance.size() != n))
        throw std::invalid_argument("denoise: the image and its guides differ in size");
}

}  // namespace

struct Denoiser::Workspace {
    Image image, scratch;
    std::vector<float> variance;
};

Denoiser::Denoiser() : workspace_(std::make_unique<Workspace>()) {}
Denoiser::~Denoiser() = default;

void Denoiser::operator()(std::vector<float>& rgb, const DenoiseGuides& guides, int passes) {
    checkSizes(rgb, guides);
    if (rgb.empty()) return;
    Workspace& w = *workspace_;
    demodulate(rgb, guides, w.image);
    if (guides.variance.empty()) estimateVariance(w.image, w.variance);
    w.scratch = w.image;
    for (int i = 0; i < passes; ++i) atrousPass(w.image, w.scratch, w.variance, 1 << i);
    remodulate(w.image, guides, rgb);
}

void denoise(std::vector<float>& rgb, const DenoiseGuides& guides, int passes) {
    Denoiser denoiser;
    denoiser(rgb, guides, passes);
}

}  // namespace rend::render
