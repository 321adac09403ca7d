// Tests for render/Look.h (the material looks with the diffusing quantity as a layer) and
// render/ToneMap.h (the filmic curve both renderers encode through).

#include "render/Look.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "TestSupport.h"
#include "render/ColorMap.h"
#include "render/EmbreeRenderer.h"
#include "render/Image.h"
#include "render/LatticeSurface.h"
#include "render/OsmesaRenderer.h"
#include "render/ToneMap.h"

namespace render = rend::render;
using render::Look;
using render::MaterialKind;
using render::Shading;

namespace {

constexpr std::array<Look, 5> kLooks = {Look::Plain, Look::Foil, Look::Film, Look::Seaweed,
                                        Look::Paper};

Shading at(Look look, float theta, float damage = 0.0f) {
    return render::layeredShading(look, render::lookPreset(look), theta, damage);
}

double luminance(const Eigen::Vector3f& c) {
    return 0.2126 * c.x() + 0.7152 * c.y() + 0.0722 * c.z();
}

// HSV hue in degrees, [0, 360).
double hue(const Eigen::Vector3f& c) {
    const float hi = c.maxCoeff();
    const float span = hi - c.minCoeff();
    double h = 0.0;
    if (hi == c.x())
        h = 60.0 * (c.y() - c.z()) / span;
    else if (hi == c.y())
        h = 120.0 + 60.0 * (c.z() - c.x()) / span;
    else
        h = 240.0 + 60.0 * (c.x() - c.y()) / span;
    return h < 0.0 ? h + 360.0 : h;
}

}  // namespace

// ---- Looks ----------------------------------------------------------------------------------

TEST(Look, ThetaAndDamageZeroGiveThePlainMaterial) {
    for (Look look : kLooks) {
        const Shading base = render::lookPreset(look);
        const Shading s = at(look, 0.0f, 0.0f);
        EXPECT_EQ(s.kind, base.kind);
        EXPECT_EQ(s.color, base.color);
        EXPECT_EQ(s.roughness, base.roughness);
        EXPECT_EQ(s.transmission, base.transmission);
    }
}

TEST(Look, NoLayerChangesTheMaterialKindAndEveryValueStaysInRange) {
    for (Look look : kLooks) {
        for (float t : {0.0f, 0.3f, 0.7f, 1.0f, 5.0f, -1.0f, std::nanf("")}) {
            for (float d : {0.0f, 0.5f, 1.0f}) {
                const Shading s = at(look, t, d);
                EXPECT_EQ(s.kind, render::lookPreset(look).kind);
                EXPECT_TRUE((s.color.array() >= 0.0f).all() && (s.color.array() <= 1.0f).all());
                EXPECT_GE(s.roughness, 0.0f);
                EXPECT_LE(s.roughness, 1.0f);
                EXPECT_GE(s.transmission, 0.0f);
                EXPECT_LE(s.transmission, 1.0f);
            }
        }
    }
}

TEST(Look, FoilStaysABrightMetalAtAnyTheta) {
    for (float t = 0.0f; t <= 1.0f; t += 0.05f) {
        const Shading s = at(Look::Foil, t, 1.0f);
        EXPECT_EQ(s.metalness(), 1.0f);
        // A temper tint, not a paint: the reflectance stays that of a bright metal.
        EXPECT_GT(luminance(s.color), 0.5) << "theta " << t;
    }
}

TEST(Look, FoilHeatTintTurnsOneWayRoundTheColourWheelAsThetaGrows) {
    // Unwrapped hue: straw and bronze (yellow-orange), then purple and blue, i.e. decreasing
    // through red. Below theta 0.3 the tint only deepens the straw.
    double previous = hue(at(Look::Foil, 0.3f).color);
    double unwrapped = previous;
    const double start = previous;
    for (float t = 0.32f; t <= 1.0f; t += 0.02f) {
        const double h = hue(at(Look::Foil, t).color);
        double step = h - previous;
        if (step > 180.0) step -= 360.0;
        if (step < -180.0) step += 360.0;
        EXPECT_LE(step, 1e-6) << "theta " << t;
        unwrapped += step;
        previous = h;
    }
    EXPECT_LT(unwrapped, start - 150.0);  // straw to blue is a real change of colour
    EXPECT_GT(render::heatTint(0.15f).minCoeff(), 0.75f);  // gentle at low heat
}

TEST(Look, WetPaperIsDarkerAndMoreTransmissiveThanDry) {
    const Shading dry = at(Look::Paper, 0.0f);
    const Shading wet = at(Look::Paper, 1.0f);
    EXPECT_LT(luminance(wet.color), 0.7 * luminance(dry.color));
    EXPECT_GT(wet.transmission, dry.transmission + 0.2f);
    EXPECT_EQ(wet.kind, MaterialKind::Translucent);
    EXPECT_GT(luminance(dry.color), 0.7);  // dry paper towel is white
}

TEST(Look, DampSeaweedIsDarkerGlossierAndStillGreen) {
    const Shading dry = at(Look::Seaweed, 0.0f);
    const Shading damp = at(Look::Seaweed, 1.0f);
    EXPECT_LT(damp.roughness, dry.roughness - 0.2f);
    EXPECT_LT(luminance(damp.color), luminance(dry.color));
    for (const Shading& s : {dry, damp}) {
        EXPECT_GT(s.color.y(), s.color.x());
        EXPECT_GT(s.color.y(), s.color.z());
    }
}

TEST(Look, EtchedFilmIsRougherAndLessTransmissiveButStillTranslucent) {
    const Shading clear = at(Look::Film, 0.0f);
    const Shading etched = at(Look::Film, 1.0f);
    EXPECT_GT(etched.roughness, clear.roughness + 0.3f);
    EXPECT_LT(etched.transmission, 0.5f * clear.transmission);
    EXPECT_GT(etched.transmission, 0.0f);
    // Yellowed: blue falls more than red.
    EXPECT_LT(etched.color.z() / etched.color.x(), clear.color.z() / clear.color.x());
}

TEST(Look, LayerMovesMonotonicallyWithTheta) {
    float lastPaper = 2.0f, lastSeaweed = 2.0f, lastFilm = -1.0f;
    for (float t = 0.0f; t <= 1.0f; t += 0.1f) {
        EXPECT_LE(luminance(at(Look::Paper, t).color), lastPaper);
        EXPECT_LE(at(Look::Seaweed, t).roughness, lastSeaweed);
        EXPECT_GE(at(Look::Film, t).roughness, lastFilm);
        lastPaper = float(luminance(at(Look::Paper, t).color));
        lastSeaweed = at(Look::Seaweed, t).roughness;
        lastFilm = at(Look::Film, t).roughness;
    }
}

TEST(Look, ParticleColorsCarryTheLayerAndThePaperMapStaysAnOption) {
    rend::test::GridSheet sheet(2, 2, 1.0);
    rend::sim::FrameView view = sheet.view();
    const std::vector<double> theta{0.0, 0.05, 0.1, 0.2};
    view.theta = theta;
    render::RenderSettings settings;
    settings.look = Look::Paper;
    render::applyLookPreset(settings);
    settings.colorBy = render::ColorBy::Theta;
    settings.colorRange = std::array<double, 2>{0.0, 0.2};
    const auto layers = render::particleLayers(view, settings);
    ASSERT_EQ(layers.size(), theta.size());
    EXPECT_FLOAT_EQ(layers[2].x(), 0.5f);
    const auto colors = render::particleColors(view, settings);
    EXPECT_TRUE(colors[3].isApprox(at(Look::Paper, 1.0f).color));
    EXPECT_TRUE(colors[0].isApprox(settings.albedo.cast<float>()));

    settings.thetaStyle = render::ThetaStyle::PaperMap;
    EXPECT_TRUE(render::particleLayers(view, settings).empty());
    EXPECT_TRUE(render::particleColors(view, settings)[3].isApprox(render::thetaColormap(1.0)));
}

TEST(Look, LatticeSurfaceCarriesALayerPerVertex) {
    rend::test::GridSheet sheet(4, 3, 1.0);
    rend::sim::FrameView view = sheet.view();
    const std::vector<double> theta(view.particleCount(), 0.1);
    view.theta = theta;
    render::RenderSettings settings;
    settings.look = Look::Foil;
    settings.colorBy = render::ColorBy::Theta;
    const render::Mesh mesh = render::LatticeSurface(view).build(view, settings);
    ASSERT_EQ(mesh.layers.size(), mesh.positions.size());
    for (const auto& l : mesh.layers) EXPECT_FLOAT_EQ(l.x(), 1.0f);  // 0.1 of a 0..0.1 range
}

namespace {

// A flat 2 x 1 sheet seen from above, lit by a high sun, whose left half (x < 0) is soaked:
// wet paper must render darker than dry paper in both renderers.
render::Mesh halfWetSheet(const render::RenderSettings& settings) {
    constexpr int kNx = 21, kNy = 11;
    render::Mesh mesh = rend::test::gridMesh(kNx, kNy, [](int i, int j) {
        const Eigen::Vector3f p(-1.0f + 0.1f * float(i), -0.5f + 0.1f * float(j), 0.0f);
        return rend::test::GridVertex{p, Eigen::Vector3f::UnitZ(), Eigen::Vector3f::Zero()};
    });
    const render::Shading base = render::baseShading(settings);
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
        const float wet = mesh.positions[v].x() < 0.0f ? 1.0f : 0.0f;
        mesh.layers.emplace_back(wet, 0.0f);
        mesh.colors[v] = render::layeredShading(settings.look, base, wet, 0.0f).color;
    }
    return mesh;
}

render::RenderSettings paperFromAbove() {
    render::RenderSettings settings;
    settings.look = Look::Paper;
    render::applyLookPreset(settings);
    settings.width = 96;
    settings.height = 64;
    settings.camera.position = Eigen::Vector3d(0.0, -0.3, 2.5);
    settings.camera.lookAt = Eigen::Vector3d::Zero();
    settings.sun.direction = Eigen::Vector3d(0.2, -0.3, 1.0);
    settings.ground = false;
    settings.pathTracing.samplesPerPixel = 8;
    return settings;
}

// Mean Rec. 709 luma of a block of pixels around (x, y).
double meanLuma(const render::Image& image, int x, int y) {
    double sum = 0.0;
    int n = 0;
    for (int j = y - 4; j <= y + 4; ++j) {
        for (int i = x - 4; i <= x + 4; ++i) {
            const std::uint8_t* p = &image.rgb[(std::size_t(j) * image.width + i) * 3];
            sum += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
            ++n;
        }
    }
    return sum / n;
}

}  // namespace

TEST(Look, WetPaperRendersDarkerThanDryInBothRenderers) {
    const render::RenderSettings settings = paperFromAbove();
    const render::Mesh mesh = halfWetSheet(settings);
    const render::Image traced = render::EmbreeRenderer().render(mesh, settings);
    const render::Image raster = render::OsmesaRenderer().render(mesh, settings);
    for (const render::Image* image : {&traced, &raster}) {
        const double wet = meanLuma(*image, image->width / 2 - 18, image->height / 2);
        const double dry = meanLuma(*image, image->width / 2 + 18, image->height / 2);
        EXPECT_LT(wet, dry - 25.0) << (image == &traced ? "embree" : "osmesa");
        EXPECT_GT(dry, 150.0);  // dry paper towel reads as white
    }
}

namespace {

// A crinkled 2 x 1.2 foil with one heat spot (theta 1 at its centre, falling off over 0.5),
// as a mesh with per-vertex layers: the temper rings of the foil look, in a reference image.
render::Mesh heatedFoil(const render::RenderSettings& settings) {
    constexpr int kNx = 41, kNy = 25;
    auto height = [](float x, float y) {
        return 0.06f * std::sin(9.0f * x + 2.0f * y) + 0.04f * std::sin(13.0f * y - 4.0f * x);
    };
    render::Mesh mesh = rend::test::gridMesh(kNx, kNy, [&](int i, int j) {
        const float x = -1.0f + 0.05f * float(i), y = -0.6f + 0.05f * float(j);
        const float h = 1e-3f;
        const float gx = (height(x + h, y) - height(x - h, y)) / (2 * h);
        const float gy = (height(x, y + h) - height(x, y - h)) / (2 * h);
        return rend::test::GridVertex{Eigen::Vector3f(x, y, height(x, y)),
                                      Eigen::Vector3f(-gx, -gy, 1.0f).normalized(),
                                      Eigen::Vector3f::Zero()};
    });
    const render::Shading base = render::baseShading(settings);
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
        const float r = Eigen::Vector2f(mesh.positions[v].x() - 0.2f, mesh.positions[v].y()).norm();
        const float theta = std::max(0.0f, 1.0f - r / 0.5f);
        mesh.layers.emplace_back(theta, 0.0f);
        mesh.colors[v] = render::layeredShading(settings.look, base, theta, 0.0f).color;
    }
    return mesh;
}

render::RenderSettings foilView() {
    render::RenderSettings settings;
    settings.look = Look::Foil;
    render::applyLookPreset(settings);
    settings.width = 160;
    settings.height = 90;
    settings.camera.position = Eigen::Vector3d(0.3, -2.2, 1.6);
    settings.camera.lookAt = Eigen::Vector3d(0.0, 0.0, -0.1);
    settings.sun.direction = Eigen::Vector3d(-0.3, 0.8, 0.9);
    settings.groundHeight = -0.4;
    settings.pathTracing.samplesPerPixel = 16;
    settings.pathTracing.maxDepth = 3;
    settings.pathTracing.skyZenith = Eigen::Vector3d(0.12, 0.16, 0.26);
    settings.pathTracing.skyHorizon = Eigen::Vector3d(0.95, 0.93, 0.88);
    return settings;
}

}  // namespace

TEST(Look, HeatedFoilMatchesItsReferenceImagesInBothRenderers) {
    const render::RenderSettings settings = foilView();
    const render::Mesh mesh = heatedFoil(settings);
    rend::test::expectMatchesReference(render::EmbreeRenderer().render(mesh, settings),
                                       "look_embree_foil");
    rend::test::expectMatchesReference(render::OsmesaRenderer().render(mesh, settings),
                                       "look_osmesa_foil");
}

// ---- Tone curve -----------------------------------------------------------------------------

TEST(ToneMap, FilmicCurveIsMonotonicAndNeverReachesWhite) {
    double previous = 0.0;
    for (double x = 1e-4; x < 1e4; x *= 1.05) {
        const double y = render::filmicCurve(x);
        EXPECT_GT(y, previous) << "x " << x;
        EXPECT_LT(y, 1.0) << "x " << x;
        previous = y;
    }
    EXPECT_GT(render::filmicCurve(100.0), 0.99);
    EXPECT_EQ(render::filmicCurve(0.0), 0.0);
}

TEST(ToneMap, HighlightsRollOffWhereAClampWouldClip) {
    const render::ToneMapping filmic;
    const render::ToneMapping clamp{render::ToneCurve::Clamp, 0.0};
    EXPECT_LT(render::toneMap(4.0, filmic), render::toneMap(16.0, filmic));
    EXPECT_EQ(render::toneMap(4.0, clamp), render::toneMap(16.0, clamp));
    EXPECT_LT(render::displayByte(2.0, filmic), 255);
    EXPECT_EQ(render::displayByte(2.0, clamp), 255);
}

TEST(ToneMap, EighteenPercentGreyStaysMidGrey) {
    const double y = render::toneMap(0.18, render::ToneMapping{});
    EXPECT_GT(y, 0.12);
    EXPECT_LT(y, 0.30);
    // Displayed: within the middle third of the byte range.
    const int byte = render::displayByte(0.18, render::ToneMapping{});
    EXPECT_GT(byte, 85);
    EXPECT_LT(byte, 170);
}

// displayByte searches thresholds rather than calling pow: the bytes of the formula, for values
// on, next to and between every threshold, and across the range, both curves and exposures.
TEST(ToneMap, TheDisplayByteIsTheGammaFormulasOwn) {
    const auto formula = [](double linear, const render::ToneMapping& tone) {
        const double c = std::pow(render::toneMap(linear, tone), 1.0 / 2.2);
        return int(std::lround(std::clamp(c, 0.0, 1.0) * 255.0));
    };
    const render::ToneMapping clamp{render::ToneCurve::Clamp, 0.0};
    std::vector<double> values{
        0.0, -1.0, 1.0, 2.0, 1e-300, std::nan(""), std::numeric_limits<double>::infinity()};
    for (int k = 1; k < 256; ++k) {
        double at = std::pow((k - 0.5) / 255.0, 2.2);
        for (int step = 0; step < 8; ++step) at = std::nextafter(at, 0.0);
        for (int step = 0; step < 17; ++step, at = std::nextafter(at, 2.0)) values.push_back(at);
        values.push_back(std::pow((k - 0.25) / 255.0, 2.2));
    }
    int checked = 0, differ = 0;
    for (const double v : values)
        differ += render::displayByte(v, clamp) != formula(v, clamp), ++checked;
    for (const double exposure : {-2.0, 0.0, 1.5})
        for (const render::ToneCurve curve :
             {render::ToneCurve::Filmic, render::ToneCurve::Clamp}) {
            const render::ToneMapping tone{curve, exposure};
            for (int i = 0; i <= 200000; ++i) {
                const double v = 4.0 * i / 200000.0;
                differ += render::displayByte(v, tone) != formula(v, tone), ++checked;
            }
        }
    EXPECT_EQ(differ, 0) << "of " << checked;
    EXPECT_EQ(render::displayByte(std::pow(254.5 / 255.0, 2.2), clamp),
              formula(std::pow(254.5 / 255.0, 2.2), clamp));
}

// A frame's channels at once (both renderers' images): each value's own displayByte, over the
// thresholds, the range, the bad values and a block's end, in double and in float.
TEST(ToneMap, AFramesBytesAreEachValuesOwn) {
    std::vector<double> values{0.0,    -1.0,         2.0,
                               1e-300, std::nan(""), std::numeric_limits<double>::infinity()};
    for (int k = 1; k < 256; ++k) {
        double at = std::pow((k - 0.5) / 255.0, 2.2);
        for (int step = 0; step < 3; ++step) at = std::nextafter(at, 0.0);
        for (int step = 0; step < 7; ++step, at = std::nextafter(at, 2.0)) values.push_back(at);
    }
    for (int i = 0; i < 3001; ++i) values.push_back(4.0 * i / 3000.0);  // not whole blocks
    const std::vector<float> floats(values.begin(), values.end());
    for (const double exposure : {-2.0, 0.0, 1.5})
        for (const render::ToneCurve curve :
             {render::ToneCurve::Filmic, render::ToneCurve::Clamp}) {
            const render::ToneMapping tone{curve, exposure};
            std::vector<std::uint8_t> bytes(values.size(), 7), fromFloats(values.size(), 7);
            render::displayBytes(values, bytes, tone);
            render::displayBytes(floats, fromFloats, tone);
            int differ = 0;
            for (std::size_t i = 0; i < values.size(); ++i) {
                differ += bytes[i] != render::displayByte(values[i], tone);
                differ += fromFloats[i] != render::displayByte(double(floats[i]), tone);
            }
            EXPECT_EQ(differ, 0) << "of " << 2 * values.size() << ", exposure " << exposure;
        }
}

TEST(ToneMap, ExposureIsInStopsAndBadRadianceIsBlack) {
    const render::ToneMapping plusOne{render::ToneCurve::Filmic, 1.0};
    EXPECT_DOUBLE_EQ(render::toneMap(0.25, plusOne), render::filmicCurve(0.5));
    EXPECT_EQ(render::toneMap(std::nan(""), plusOne), 0.0);
    EXPECT_EQ(render::toneMap(-1.0, plusOne), 0.0);
    EXPECT_EQ(render::toneMap(std::numeric_limits<double>::infinity(), plusOne), 1.0);
}
