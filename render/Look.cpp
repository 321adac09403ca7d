#include "render/Look.h"

#include <algorithm>
#include <cmath>

#include "render/ColorMap.h"

namespace rend::render {

namespace {

using Vec3 = Eigen::Vector3f;

Vec3 lerp(const Vec3& a, const Vec3& b, float t) { return a + (b - a) * t; }
float lerp(float a, float b, float t) { return a + (b - a) * t; }
float unit(float x) { return std::isfinite(x) ? std::clamp(x, 0.0f, 1.0f) : 0.0f; }

// Temper colours of a thin oxide film as a factor on the bare metal's reflectance, at theta
// 0, 0.3, 0.6, 0.8 and 1 (thin-film interference, read off tempering charts: straw, bronze,
// purple, blue), short of full saturation: an oxide tints the foil, it does not paint it. Linear
// interpolation keeps the hue monotonic, since each straight segment between these keys sweeps
// less than half way round the grey axis.
constexpr float kTintAt[5] = {0.0f, 0.3f, 0.6f, 0.8f, 1.0f};
constexpr float kTint[5][3] = {
    {1.00f, 1.00f, 1.00f}, {1.00f, 0.88f, 0.62f}, {0.93f, 0.68f, 0.46f},
    {0.72f, 0.55f, 0.82f}, {0.52f, 0.64f, 0.98f},
};

// Wet and damp surfaces: water fills the pores, so less light scatters back out (darker) and
// more passes through (paper), and a water film smooths the surface (glossier nori). The
// target values are eyeballed from photographs of wet paper towel and damp nori.
constexpr float kDampRoughness = 0.22f;  // seaweed under a water film
constexpr float kDampDarkening = 0.45f;  // nori albedo factor where fully damp
constexpr float kWetDarkening = 0.30f;   // paper albedo factor where soaked
constexpr float kWetTransmission = 0.80f;
// Acid etching frosts a clear film: micro-pits scatter (rough, clouded) and yellow it.
constexpr float kEtchedRoughness = 0.80f;
constexpr float kEtchedClarity = 0.40f;  // fraction of the transmission left where fully etched
const Vec3 kEtchYellow{1.00f, 0.93f, 0.68f};
// Stress whitening of a polymer near a tear, and the pale fibres of a torn paper edge.
const Vec3 kWhitened{0.85f, 0.84f, 0.80f};

Shading foil(Shading s, float t, float d) {
    s.color = s.color.cwiseProduct(heatTint(t));
    // The oxide and the crumpling at a tear both scatter a little more.
    s.roughness = std::min(1.0f, s.roughness + 0.08f * t + 0.12f * d);
    return s;
}

// How wet a surface looks at moisture t: the first water fills the pores and does most of the
// darkening, so the response eases out (monotonic, 0 at 0, 1 at 1).
float wetness(float t) { return 1.0f - (1.0f - t) * (1.0f - t); }

Shading seaweed(Shading s, float t) {
    const float w = wetness(t);
    s.color *= lerp(1.0f, kDampDarkening, w);
    s.roughness = lerp(s.roughness, std::min(s.roughness, kDampRoughness), w);
    return s;
}

Shading film(Shading s, float t, float d) {
    s.color = lerp(s.color.cwiseProduct(lerp(Vec3::Ones(), kEtchYellow, t)), kWhitened, 0.4f * d);
    s.roughness = lerp(s.roughness, std::max(s.roughness, kEtchedRoughness), t);
    s.transmission *= lerp(1.0f, kEtchedClarity, t) * (1.0f - 0.5f * d);
    return s;
}

Shading paper(Shading s, float t, float d) {
    const float w = wetness(t);
    s.color = lerp(s.color * lerp(1.0f, kWetDarkening, w), kWhitened, 0.3f * d);
    s.transmission = lerp(s.transmission, std::max(s.transmission, kWetTransmission), w);
    return s;
}

// A plain material takes theta as a dye: the paper's red map divided by its own low end, so
// that theta = 0 leaves the colour alone.
Shading plain(Shading s, float t) {
    const Vec3 stain = thetaColormap(t).cwiseQuotient(thetaColormap(0.0));
    s.color = s.color.cwiseProduct(stain).cwiseMin(1.0f);
    return s;
}

}  // namespace

Eigen::Vector3f heatTint(float theta) {
    const float t = unit(theta);
    int k = 0;
    while (k < 3 && t > kTintAt[k + 1]) ++k;
    const float f = (t - kTintAt[k]) / (kTintAt[k + 1] - kTintAt[k]);
    return lerp(Vec3(kTint[k][0], kTint[k][1], kTint[k][2]),
                Vec3(kTint[k + 1][0], kTint[k + 1][1], kTint[k + 1][2]), f);
}

Shading lookPreset(Look look) {
    switch (look) {
        case Look::Foil:  // aluminium's F0 (linear), a rolled foil's satin finish
            return {MaterialKind::Conductor, Vec3(0.91f, 0.92f, 0.92f), 0.22f, 0.0f};
        case Look::Film:  // an amber, mostly clear rubbery film with a sharp gloss
            return {MaterialKind::Film, Vec3(0.82f, 0.55f, 0.22f), 0.12f, 0.75f};
        case Look::Seaweed:  // nori: near-black green with a dull sheen; the film lobe with no
                             // transmission is a gloss over a diffuse base
            return {MaterialKind::Film, Vec3(0.020f, 0.045f, 0.022f), 0.55f, 0.0f};
        case Look::Paper:  // white paper towel, a thin diffuser that lets some light through
            return {MaterialKind::Translucent, Vec3(0.90f, 0.90f, 0.88f), 0.8f, 0.35f};
        case Look::Plain:
            break;
    }
    return baseShading(RenderSettings{});
}

void applyLookPreset(RenderSettings& settings) {
    const Shading preset = lookPreset(settings.look);
    settings.pathTracing.material = preset.kind;
    settings.albedo = preset.color.cast<double>();
    settings.pathTracing.roughness = preset.roughness;
    settings.pathTracing.transmission = preset.transmission;
}

Shading baseShading(const RenderSettings& settings) {
    const PathTracing& pt = settings.pathTracing;
    return {pt.material, settings.albedo.cast<float>(), float(pt.roughness),
            float(pt.transmission)};
}

Shading layeredShading(Look look, const Shading& base, float theta, float damage) {
    const float t = unit(theta);
    const float d = unit(damage);
    switch (look) {
        case Look::Foil:
            return foil(base, t, d);
        case Look::Seaweed:
            return seaweed(base, t);
        case Look::Film:
            return film(base, t, d);
        case Look::Paper:
            return paper(base, t, d);
        case Look::Plain:
            break;
    }
    return plain(base, t);
}

bool usesLookLayer(const RenderSettings& settings) {
    return settings.colorBy == ColorBy::None ||
           (settings.colorBy == ColorBy::Theta && settings.thetaStyle == ThetaStyle::Layer);
}

}  // namespace rend::render
