#include "app/MaterialMapLoader.h"

#include <filesystem>
#include <string>
#include <system_error>

#include "app/SceneNames.h"
#include "render/Image.h"

namespace rend {
namespace {

using scene::TableReader;

constexpr double kMostImagePixels = 64e6;
constexpr std::uintmax_t kMostImageBytes = 256u << 20;

/// The keys each shape takes; a key of another shape is an error, so a forgotten shape cannot
/// silently change the map.
void requireForShape(const TableReader& t, sim::MapShape shape) {
    struct Rule {
        std::string_view key;
        sim::MapShape shape;
        bool required;
    };
    using S = sim::MapShape;
    constexpr Rule kRules[] = {
        {"factor", S::Box, true},       {"min", S::Box, true},        {"max", S::Box, true},
        {"factor", S::Disc, true},      {"center", S::Disc, true},    {"radius", S::Disc, true},
        {"factor", S::Polygon, true},   {"points", S::Polygon, true}, {"scale", S::Noise, false},
        {"amplitude", S::Noise, false}, {"octaves", S::Noise, false}, {"seed", S::Noise, false},
        {"file", S::Image, true},       {"low", S::Image, false},     {"high", S::Image, false}};
    const std::string name(names::kMapShapes[std::size_t(shape)]);
    for (const Rule& r : kRules)
        if (r.shape == shape && r.required && !t.has(r.key))
            t.missing(r.key, "for shape = \"" + name + "\"");
    for (const Rule& r : kRules) {
        bool allowed = false;
        for (const Rule& s : kRules) allowed = allowed || (s.key == r.key && s.shape == shape);
        if (!allowed && t.has(r.key)) {
            t.fail(r.key, "no " + std::string(r.key) + " for shape = \"" + name + "\"",
                   scene::describeType(*t.find(r.key)),
                   "Remove " + std::string(r.key) + ", or change the shape.");
        }
    }
}

sim::GreyImage readImage(const TableReader& t, const Scene& scene) {
    const std::filesystem::path file = scene.file.parent_path() / *t.string("file");
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec) ||
        std::filesystem::file_size(file, ec) > kMostImageBytes) {
        t.fail("file", "a PNG file of at most 256 MiB", file.string(),
               "Give a path relative to the scene file, to a PNG image.");
    }
    render::Image rgb;
    try {
        rgb = render::readPng(file);
    } catch (const std::exception& e) {
        t.fail("file", "a PNG image", e.what(), "Give a path relative to the scene file.");
    }
    if (double(rgb.width) * rgb.height > kMostImagePixels) {
        t.fail("file", "an image of at most 64 megapixels",
               std::to_string(rgb.width) + " x " + std::to_string(rgb.height),
               "Scale the image down: the sheet's particles sample it.");
    }
    sim::GreyImage grey{rgb.width, rgb.height, {}};
    grey.values.resize(std::size_t(rgb.width) * rgb.height);
    for (std::size_t p = 0; p < grey.values.size(); ++p)  // the mean of the display values
        grey.values[p] = float(rgb.rgb[3 * p] + rgb.rgb[3 * p + 1] + rgb.rgb[3 * p + 2]) / 765.0f;
    return grey;
}

/// The smallest and largest factor a map gives, and the key that sets them.
struct FactorRange {
    double low, high;
    std::string_view key;
};

FactorRange factorRange(const sim::MaterialMap& m) {
    switch (m.shape) {
        case sim::MapShape::Noise:
            return {1.0 - m.amplitude, 1.0 + m.amplitude, "amplitude"};
        case sim::MapShape::Image:
            return {m.low, m.high, "low"};
        default:  // 1 outside the region
            return {std::min(1.0, m.factor), std::max(1.0, m.factor), "factor"};
    }
}

/// A map of the bond law's parameters needs that law, and a power-law exponent map must keep n
/// in the schema's (1, 100] with the maps before it (they multiply).
void checkLawMap(const TableReader& t, const sim::MaterialMap& m,
                 const sim::MaterialParams& material, double& exponentLow, double& exponentHigh) {
    using P = sim::MappedProperty;
    const std::string name = "\"" + sim::mappedPropertyName(m.property) + "\"";
    const bool yieldMap = m.property == P::YieldStrain || m.property == P::Softening;
    const bool powerMap = m.property == P::PowerRatio || m.property == P::PowerExponent;
    if (yieldMap && material.law != sim::BondLawKind::Elastoplastic) {
        t.fail("property", "a material with law = \"elastoplastic\"", name,
               "Give [material] law = \"elastoplastic\", or map another property.");
    }
    if (powerMap && material.law != sim::BondLawKind::PowerLaw) {
        t.fail("property", "a material with law = \"power_law\"", name,
               "Give [material] law = \"power_law\", or map another property.");
    }
    if (m.property == P::PowerRatio && material.powerLawRatio == 0.0) {
        t.fail("property", "a material with power_ratio below 0 (a factor on 0 changes nothing)",
               name, "Give [material] power_ratio, e.g. -0.1, or map another property.");
    }
    if (m.property != P::PowerExponent) return;
    const FactorRange range = factorRange(m);
    exponentLow *= range.low, exponentHigh *= range.high;
    const double n = material.powerLawExponent;
    if (!(n * exponentLow > 1.0) || !(n * exponentHigh <= 100.0)) {
        t.fail(range.key, "factors that keep power_exponent in (1, 100]",
               "n from " + scene::formatNumber(n * exponentLow) + " to " +
                   scene::formatNumber(n * exponentHigh),
               "Narrow the map's factors, or change [material] power_exponent.");
    }
}

sim::MaterialMap readMap(const TableReader& t, const Scene& scene, double& exponentLow,
                         double& exponentHigh) {
    sim::MaterialMap m;
    if (!t.has("property")) t.missing("property", scene::oneOf(names::kMappedProperties));
    if (!t.has("shape")) t.missing("shape", scene::oneOf(names::kMapShapes));
    m.property = sim::MappedProperty(*t.choice("property"));
    m.shape = sim::MapShape(*t.choice("shape"));
    requireForShape(t, m.shape);
    m.factor = t.number("factor").value_or(m.factor);
    m.min = t.vec2("min").value_or(m.min);
    m.max = t.vec2("max").value_or(m.max);
    m.center = t.vec2("center").value_or(m.center);
    m.radius = t.number("radius").value_or(m.radius);
    if (t.has("points")) m.polygon = *t.points("points", 3);
    m.scale = t.vec2("scale").value_or(m.scale);
    m.amplitude = t.number("amplitude").value_or(m.amplitude);
    m.octaves = int(t.integer("octaves").value_or(m.octaves));
    m.seed = std::uint64_t(t.integer("seed").value_or(std::int64_t(m.seed)));
    m.low = t.number("low").value_or(m.low);
    m.high = t.number("high").value_or(m.high);
    if (m.shape == sim::MapShape::Image) m.image = readImage(t, scene);
    checkLawMap(t, m, scene.sim.material, exponentLow, exponentHigh);
    if (m.property == sim::MappedProperty::FractureEnergy && !scene.sim.material.fractureEnergy) {
        t.fail("property", "a material that breaks (fracture_energy is \"none\")",
               "\"fracture_energy\"", "Give [material] fracture_energy, or map another property.");
    }
    return m;
}

}  // namespace

void readMaterialMaps(const TableReader& root, Scene& scene) {
    const TableReader material = root.section("material");
    double exponentLow = 1.0, exponentHigh = 1.0;  // the product of the exponent maps' factors
    for (const TableReader& entry : material.entries("map"))
        scene.sim.materialMaps.push_back(readMap(entry, scene, exponentLow, exponentHigh));
}

}  // namespace rend
