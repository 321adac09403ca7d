#include "render/ColorMap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include "render/Look.h"

namespace rend::render {

namespace {

// Viridis sampled at nine evenly spaced points, in sRGB; interpolating in sRGB keeps the
// perceptual spacing the map was designed for, and the result is linearised at the end.
constexpr float kViridisSrgb[9][3] = {
    {0.267f, 0.005f, 0.329f}, {0.283f, 0.141f, 0.458f}, {0.229f, 0.322f, 0.546f},
    {0.173f, 0.449f, 0.558f}, {0.128f, 0.567f, 0.551f}, {0.135f, 0.659f, 0.518f},
    {0.369f, 0.789f, 0.383f}, {0.678f, 0.864f, 0.190f}, {0.993f, 0.906f, 0.144f},
};

// Light red -> dark red, the membrane paper's look for increasing theta, in sRGB. The middle
// sample keeps the midrange a saturated red; a straight line between the ends passes through a
// greyish rose. Every channel falls monotonically, so luminance does too.
constexpr float kThetaSrgb[3][3] = {
    {1.00f, 0.85f, 0.82f},
    {0.84f, 0.30f, 0.26f},
    {0.45f, 0.00f, 0.02f},
};

float srgbToLinear(float c) { return std::pow(c, 2.2f); }

// Piecewise-linear interpolation of an sRGB table at t in [0,1], linearised at the end.
template <std::size_t N>
Eigen::Vector3f sampleSrgb(const float (&table)[N][3], double t) {
    static_assert(N >= 2);
    const double clamped = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0);
    const double x = clamped * double(N - 1);
    const int k = std::min(static_cast<int>(x), static_cast<int>(N) - 2);
    const float f = static_cast<float>(x - k);
    Eigen::Vector3f c;
    for (int ch = 0; ch < 3; ++ch) {
        const float s = table[k][ch] * (1.0f - f) + table[k + 1][ch] * f;
        c[ch] = srgbToLinear(s);
    }
    return c;
}

// A field stored by the simulator (theta, damage); zeros where the frame has none, so that a
// scene without that physics renders as the low end rather than failing.
std::vector<double> storedField(const sim::FrameView& frame, std::span<const double> values) {
    std::vector<double> out(frame.particleCount(), 0.0);
    std::copy_n(values.begin(), std::min(out.size(), values.size()), out.begin());
    return out;
}

std::vector<double> speeds(const sim::FrameView& frame) {
    std::vector<double> out(frame.particleCount(), 0.0);
    const std::size_t n = std::min(out.size(), frame.velocities.size());
    for (std::size_t i = 0; i < n; ++i) out[i] = frame.velocities[i].norm();
    return out;
}

double meanBondStrain(const sim::FrameView& frame, int i) {
    double sum = 0.0;
    int count = 0;
    for (int b = frame.bondOffsets[i]; b < frame.bondOffsets[i + 1]; ++b) {
        if (!frame.bondAlive.empty() && frame.bondAlive[b] == 0) continue;
        const double len = (frame.positions[frame.bondPartners[b]] - frame.positions[i]).norm();
        sum += len / frame.bondRestLength[b] - 1.0;
        ++count;
    }
    // A fully detached particle carries no load.
    return count > 0 ? sum / count : 0.0;
}

std::vector<double> strains(const sim::FrameView& frame) {
    std::vector<double> out(frame.particleCount(), 0.0);
    if (frame.bondOffsets.size() < out.size() + 1) return out;
    for (std::size_t i = 0; i < out.size(); ++i)
        out[i] = meanBondStrain(frame, static_cast<int>(i));
    return out;
}

std::array<double, 2> fieldRange(const std::vector<double>& field, const RenderSettings& settings) {
    if (settings.colorRange) return *settings.colorRange;
    double hi = 0.0;
    for (double v : field) hi = std::max(hi, v);
    // An all-zero field (a sheet at rest) must not divide by zero; map it to the low end.
    return {0.0, hi > 0.0 ? hi : 1.0};
}

}  // namespace

std::vector<double> particleField(const sim::FrameView& frame, ColorBy by) {
    switch (by) {
        case ColorBy::Speed:
            return speeds(frame);
        case ColorBy::Strain:
            return strains(frame);
        case ColorBy::Theta:
            return storedField(frame, frame.theta);
        case ColorBy::Damage:
            return storedField(frame, frame.damage);
        case ColorBy::None:
            break;
    }
    return {};
}

Eigen::Vector3f colormap(double t) { return sampleSrgb(kViridisSrgb, t); }

Eigen::Vector3f thetaColormap(double t) { return sampleSrgb(kThetaSrgb, t); }

std::vector<Eigen::Vector2f> particleLayers(const sim::FrameView& frame,
                                            const RenderSettings& settings) {
    if (!usesLookLayer(settings)) return {};
    const std::size_t n = frame.particleCount();
    std::vector<Eigen::Vector2f> layers(n, Eigen::Vector2f::Zero());
    if (settings.colorBy == ColorBy::Theta) {
        const std::vector<double> theta = particleField(frame, ColorBy::Theta);
        const auto [lo, hi] = fieldRange(theta, settings);
        for (std::size_t i = 0; i < n; ++i) layers[i].x() = float((theta[i] - lo) / (hi - lo));
    }
    const std::size_t damaged = std::min(n, frame.damage.size());
    for (std::size_t i = 0; i < damaged; ++i) layers[i].y() = float(frame.damage[i]);
    for (auto& l : layers) l = l.cwiseMax(0.0f).cwiseMin(1.0f);
    return layers;
}

std::vector<Eigen::Vector3f> particleColors(const sim::FrameView& frame,
                                            const RenderSettings& settings) {
    const std::size_t n = frame.particleCount();
    if (usesLookLayer(settings)) {
        const Shading base = baseShading(settings);
        std::vector<Eigen::Vector3f> colors;
        colors.reserve(n);
        for (const Eigen::Vector2f& l : particleLayers(frame, settings))
            colors.push_back(layeredShading(settings.look, base, l.x(), l.y()).color);
        return colors;
    }
    const std::vector<double> field = particleField(frame, settings.colorBy);
    const auto [lo, hi] = fieldRange(field, settings);
    const double span = hi - lo;
    const auto map = settings.colorBy == ColorBy::Theta ? thetaColormap : colormap;
    std::vector<Eigen::Vector3f> colors;
    colors.reserve(n);
    for (double v : field) colors.push_back(map(span > 0.0 ? (v - lo) / span : 0.0));
    return colors;
}

}  // namespace rend::render
