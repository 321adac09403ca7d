// Scene loader: reads every table by the keys declared in SceneSchema.cpp, checks what one key
// alone cannot (shapes, switches, sizes against the sheet), and records where each value came from.
// Every key present but never read is an error (KeyLog::reportUnused).

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <sstream>

#include "app/ContactLoader.h"
#include "app/MaterialMapLoader.h"
#include "app/Scene.h"
#include "app/SceneDocument.h"
#include "app/SceneError.h"
#include "app/SceneNames.h"
#include "app/SceneReader.h"
#include "render/Look.h"
#include "sim/Lattice.h"
#include "sim/SolverRegistry.h"

namespace rend {
namespace {

using scene::formatNumber;
using scene::TableReader;

enum class Edge { Left, Right, Bottom, Top };

/// The lattice, its bonds and the solvers' per-particle arrays must fit in this much memory.
constexpr double kMaxMemoryBytes = 8e9;
/// Fewer particles across than this cannot bend or stretch in any meaningful way.
constexpr double kMinParticlesAcross = 4;
/// Guards frameCount() against int overflow; ~11 hours of video at 24 fps.
constexpr double kMaxFrames = 1e6;
/// [[diffusion.scatter]] entries together; the per-step source loop visits each spot.
constexpr double kMaxScatteredSpots = 1e5;

/// Two significant digits, so limits and suggestions read like something a person would type;
/// `direction` (-1, 0, +1) rounds down, to nearest or up, to keep a quoted limit valid.
double roundForDisplay(double value, int direction = 0) {
    if (!std::isfinite(value) || value <= 0.0) return value;
    const int exponent = int(std::floor(std::log10(value))) - 1;
    const double scaled = value / std::pow(10.0, exponent);
    const double rounded = direction < 0   ? std::floor(scaled)
                           : direction > 0 ? std::ceil(scaled)
                                           : std::round(scaled);
    // Dividing by an exact power of ten keeps 45 / 1e4 printing as 0.0045.
    return exponent < 0 ? rounded / std::pow(10.0, -exponent) : rounded * std::pow(10.0, exponent);
}

struct SheetExtent {
    Eigen::Vector2d min, max;
    double smallest = 0, largest = 0, area = 0;
};

SheetExtent extentOf(const sim::SheetParams& sheet) {
    const bool round = sheet.outline != sim::Outline::Rectangle;
    const Eigen::Vector2d half =
        round ? Eigen::Vector2d(sheet.radius, sheet.radius) : Eigen::Vector2d(0.5 * sheet.size);
    SheetExtent e;
    e.min = sheet.center.head<2>() - half;
    e.max = sheet.center.head<2>() + half;
    e.smallest = 2 * half.minCoeff();
    e.largest = 2 * half.maxCoeff();
    const double r2 = sheet.radius * sheet.radius;
    e.area = sheet.outline == sim::Outline::Disc     ? std::numbers::pi * r2
             : sheet.outline == sim::Outline::Sphere ? 4.0 * std::numbers::pi * r2
                                                     : sheet.size.prod();
    return e;
}

std::string gigabytes(double bytes) { return formatNumber(roundForDisplay(bytes / 1e9)) + " GB"; }

// ---- [sheet] ---------------------------------------------------------------------------------

/// A key that only makes sense for one shape is an error for the other, so a forgotten
/// shape = "disc" cannot silently produce a rectangle.
void rejectForShape(const TableReader& t, std::string_view key, std::string_view shape,
                    std::string_view fix) {
    if (const toml::node* node = t.find(key)) {
        t.fail(key, "no " + std::string(key) + " for shape = \"" + std::string(shape) + "\"",
               scene::describeType(*node), fix);
    }
}

void readOutline(const TableReader& t, sim::SheetParams& s) {
    s.outline = sim::Outline(t.choice("shape").value_or(0));
    if (s.outline == sim::Outline::Rectangle) {
        if (!t.has("size")) t.missing("size", "2 numbers > 0");
        s.size = *t.vec2("size");
        rejectForShape(t, "radius", "rectangle", "Remove radius, or set shape = \"disc\".");
    } else {
        s.radius = t.requiredNumber("radius");
        rejectForShape(t, "size", names::kShapes[std::size_t(s.outline)],
                       "Remove size and give radius instead.");
    }
}

/// dx is bounded by the outline on both sides: coarse enough for the memory budget, fine enough
/// to resolve the sheet at all. `key` is the key that chose it (dx or dx_final).
void checkSpacing(const TableReader& t, const sim::SheetParams& s, std::string_view key) {
    const SheetExtent e = extentOf(s);
    const double maxDx = e.smallest / (kMinParticlesAcross - 1);
    if (s.dx > maxDx) {
        t.fail(key,
               "a spacing of at most " + formatNumber(roundForDisplay(maxDx, -1)) +
                   " m, so that at least 4 particles fit "
                   "across the sheet's smaller extent of " +
                   formatNumber(e.smallest) + " m",
               formatNumber(s.dx),
               "Use e.g. " + std::string(key) + " = " +
                   formatNumber(roundForDisplay(e.smallest / 50)) + ".");
    }
    const SheetEstimate estimate = estimateSheet(s);
    if (estimate.bytes > kMaxMemoryBytes) {
        // Memory grows as 1/dx^2 at a fixed horizon, so this dx fits the budget.
        const double minDx = s.dx * std::sqrt(estimate.bytes / kMaxMemoryBytes);
        t.fail(key,
               "a spacing that fits the memory limit of " + gigabytes(kMaxMemoryBytes) +
                   " (particles x (" + formatNumber(SheetEstimate::kBytesPerParticle) +
                   " bytes + bonds x " + formatNumber(SheetEstimate::kBytesPerBondEnd) +
                   " bytes)), i.e. dx >= " + formatNumber(roundForDisplay(minDx, +1)) +
                   " m at horizon = " + formatNumber(s.horizonFactor),
               formatNumber(s.dx) + ": about " + formatNumber(roundForDisplay(estimate.particles)) +
                   " particles with " + formatNumber(std::round(estimate.bondsPerParticle)) +
                   " bonds each, about " + gigabytes(estimate.bytes),
               "Use e.g. " + std::string(key) + " = " +
                   formatNumber(roundForDisplay(minDx * 2, +1)) + ", or a smaller horizon.");
    }
}

/// dx is the preview spacing; quality = "final" swaps in dx_final, else the coarsest spacing
/// that gives the sheet kFinalParticles. Seeded draws stay on the preview lattice.
void readQuality(const TableReader& t, Scene& scene) {
    sim::SheetParams& s = scene.sim.sheet;
    scene.quality = Quality(t.choice("quality").value_or(std::size_t(scene.quality)));
    const std::optional<double> dxFinal = t.number("dx_final");
    scene.previewDx = s.dx;
    s.seedSpacing = s.dx;
    if (scene.quality == Quality::Final)
        s.dx = dxFinal.value_or(sim::spacingForParticles(s, kFinalParticles));
    const bool chosen = scene.quality == Quality::Final && dxFinal;
    checkSpacing(t, s,
                 scene.quality == Quality::Final && !chosen ? "quality"
                 : chosen                                   ? "dx_final"
                                                            : "dx");
}

void readSheet(const TableReader& root, Scene& scene) {
    const TableReader t = root.section("sheet");
    sim::SheetParams& s = scene.sim.sheet;
    s.dx = t.requiredNumber("dx");
    readOutline(t, s);
    s.center = t.vec3("center").value_or(s.center);
    s.lattice = sim::LatticeKind(t.choice("lattice").value_or(std::size_t(s.lattice)));
    s.horizonFactor = t.number("horizon").value_or(s.horizonFactor);
    s.thickness = t.number("thickness").value_or(s.thickness);
    s.perturbationAmplitude = t.number("perturbation").value_or(s.perturbationAmplitude);
    s.perturbationSeed = std::uint64_t(t.integer("seed").value_or(s.perturbationSeed));
    readQuality(t, scene);
}

// ---- [material] ------------------------------------------------------------------------------

/// A key that only matters once another key is chosen ("switch") is an error when that switch
/// is absent altogether: otherwise a forgotten law = "power_law" silently gives a linear sheet.
/// A switch that is present but names something else is accepted (the key is then unused), so
/// a preset's law can be switched with --set material.law=... without editing the preset.
void requireSwitch(const TableReader& t, std::string_view key, std::string_view switchKey,
                   std::string_view needed, std::string_view fix) {
    if (t.has(switchKey)) return;
    if (const toml::node* node = t.find(key)) {
        t.fail(key,
               "no " + std::string(key) + " without " + std::string(switchKey) + " (" +
                   std::string(needed) + ")",
               scene::describeType(*node), fix);
    }
}

/// Bond law of eqs. 18-20 and its constants.
void readBondLaw(const TableReader& t, sim::MaterialParams& m) {
    requireSwitch(t, "power_ratio", "law", "it belongs to law = \"power_law\"",
                  "Add law = \"power_law\", or remove power_ratio.");
    requireSwitch(t, "power_exponent", "law", "it belongs to law = \"power_law\"",
                  "Add law = \"power_law\", or remove power_exponent.");
    requireSwitch(t, "softening", "law", "it belongs to law = \"elastoplastic\"",
                  "Add law = \"elastoplastic\", or remove softening.");
    m.law = sim::BondLawKind(t.choice("law").value_or(std::size_t(m.law)));
    m.powerLawRatio = t.number("power_ratio").value_or(m.powerLawRatio);
    m.powerLawExponent = t.number("power_exponent").value_or(m.powerLawExponent);
    // Table 1 lists eta0 for every material; only the elastoplastic law (eqs. 20, 27) uses it.
    m.yieldStrain = t.number("yield_strain").value_or(m.yieldStrain);
    m.softening = t.number("softening").value_or(m.softening);
}

/// fracture_energy is a number, or "none" for an unbreakable sheet (the default), so that a
/// preset's fracture can be switched off with --set material.fracture_energy=none.
void readFracture(const TableReader& t, sim::MaterialParams& m) {
    requireSwitch(t, "critical_stretch", "fracture_energy", "bonds never break without it",
                  "Add e.g. fracture_energy = 11.3, or remove critical_stretch.");
    requireSwitch(t, "strength_loss", "fracture_energy", "bonds never break without it",
                  "Add e.g. fracture_energy = 11.3, or remove strength_loss.");
    m.fractureEnergy = t.numberOrWord("fracture_energy", m.fractureEnergy);
    m.criticalStretch = sim::CriticalStretchMode(
        t.choice("critical_stretch").value_or(std::size_t(m.criticalStretch)));
    m.strengthLoss = t.number("strength_loss").value_or(m.strengthLoss);
    m.surfaceCorrection = t.boolean("surface_correction").value_or(m.surfaceCorrection);
}

/// The diffusive quantity theta inside the material (eq. 25) and what it does to it.
void readDiffusivity(const TableReader& t, sim::MaterialParams& m) {
    m.capacity = t.number("capacity").value_or(m.capacity);
    m.conductivity = t.number("conductivity").value_or(m.conductivity);
    m.expansion = t.number("expansion").value_or(m.expansion);
    m.stiffnessLoss = t.number("stiffness_loss").value_or(m.stiffnessLoss);
}

sim::MaterialParams readMaterial(const TableReader& root) {
    const TableReader t = root.section("material");
    sim::MaterialParams m;
    const std::optional<std::string> preset = t.string("preset");  // merged already; type-check
    m.name = t.string("name").value_or(preset.value_or(m.name));
    m.youngsModulus = t.requiredNumber("E");
    m.poissonRatio = t.number("poisson").value_or(m.poissonRatio);
    m.density = t.requiredNumber("density");
    m.micromodulus =
        sim::MicromodulusMode(t.choice("micromodulus").value_or(std::size_t(m.micromodulus)));
    readBondLaw(t, m);
    readFracture(t, m);
    readDiffusivity(t, m);
    return m;
}

// ---- [[boundary]] ----------------------------------------------------------------------------

/// The strip `depth` metres wide along one side of the sheet's rest bounding box. The outer
/// side stays unbounded and the inner one gets a hair of tolerance, so the particles exactly on
/// the strip's edges are included despite rounding in the lattice.
sim::Region edgeRegion(Edge edge, double depth, const sim::SheetParams& sheet) {
    const SheetExtent e = extentOf(sheet);
    const double width = depth + 1e-9 * sheet.dx;
    sim::Region r;
    switch (edge) {
        case Edge::Left:
            r.max.x() = e.min.x() + width;
            break;
        case Edge::Right:
            r.min.x() = e.max.x() - width;
            break;
        case Edge::Bottom:
            r.max.y() = e.min.y() + width;
            break;
        case Edge::Top:
            r.min.y() = e.max.y() - width;
            break;
    }
    return r;
}

sim::Region boxRegion(const TableReader& t) {
    const TableReader box = *t.subtable("box");
    if (!box.has("min")) box.missing("min");
    if (!box.has("max")) box.missing("max");
    sim::Region r;
    r.min = *box.vec2("min");
    r.max = *box.vec2("max");
    if ((r.min.array() >= r.max.array()).any()) {
        t.fail("box", "min < max in both x and y (" + std::string(t.param("box").meaning) + ")",
               "min = [" + formatNumber(r.min.x()) + ", " + formatNumber(r.min.y()) + "], max = [" +
                   formatNumber(r.max.x()) + ", " + formatNumber(r.max.y()) + "]",
               "Swap the offending coordinates.");
    }
    return r;
}

/// `depth` defaults to the preview spacing, one row of the preview lattice, in metres at every
/// quality.
sim::Region readRegion(const TableReader& t, const Scene& scene) {
    const sim::SheetParams& sheet = scene.sim.sheet;
    if (t.has("edge") && t.has("box")) {
        t.fail("box", "either edge or box, not both", "both", "Remove edge or box.");
    }
    if (t.has("box")) {
        if (const toml::node* depth = t.find("depth")) {
            t.fail("depth", "no depth with box (depth applies to edge regions)",
                   scene::describeType(*depth), "Remove depth, or use edge instead of box.");
        }
        return boxRegion(t);
    }
    if (!t.has("edge")) t.missing("edge", "or box = { min = [x, y], max = [x, y] }");
    const Edge edge = Edge(*t.choice("edge"));
    return edgeRegion(edge, t.number("depth").value_or(scene.previewDx), sheet);
}

/// Keys that only a velocity condition uses are errors on a pinned one, not silently ignored.
void rejectForPinned(const TableReader& t, std::string_view key) {
    if (const toml::node* node = t.find(key)) {
        t.fail(key, "no " + std::string(key) + " for type = \"pinned\"", scene::describeType(*node),
               "Remove " + std::string(key) + ", or set type = \"velocity\".");
    }
}

sim::BoundaryCondition readBoundary(const TableReader& t, const Scene& scene) {
    sim::BoundaryCondition bc;
    if (!t.has("type")) t.missing("type", "one of \"velocity\", \"pinned\"");
    bc.kind = sim::BoundaryKind(*t.choice("type"));
    bc.region = readRegion(t, scene);
    if (bc.kind == sim::BoundaryKind::Pinned) {
        rejectForPinned(t, "velocity");
        rejectForPinned(t, "ramp");
        return bc;
    }
    if (!t.has("velocity")) t.missing("velocity");
    bc.velocity = *t.vec3("velocity");
    bc.rampTime = t.number("ramp").value_or(bc.rampTime);
    return bc;
}

std::vector<sim::BoundaryCondition> readBoundaries(const TableReader& root, const Scene& scene) {
    std::vector<sim::BoundaryCondition> conditions;
    for (const TableReader& t : root.entries("boundary"))
        conditions.push_back(readBoundary(t, scene));
    return conditions;
}

// ---- [[notch]] -------------------------------------------------------------------------------

/// A notch whose polyline misses the sheet's rest bounding box cuts nothing.
void checkNotchMeetsSheet(const TableReader& t, const sim::Notch& notch,
                          const sim::SheetParams& sheet) {
    const SheetExtent e = extentOf(sheet);
    Eigen::Vector2d lo = notch.points.front(), hi = lo;
    for (const Eigen::Vector2d& p : notch.points) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
    if ((hi.array() >= e.min.array()).all() && (lo.array() <= e.max.array()).all()) return;
    t.fail("points",
           "a polyline that meets the sheet, whose rest extent is x in [" +
               formatNumber(e.min.x()) + ", " + formatNumber(e.max.x()) + "], y in [" +
               formatNumber(e.min.y()) + ", " + formatNumber(e.max.y()) + "]",
           "one within x in [" + formatNumber(lo.x()) + ", " + formatNumber(hi.x()) + "], y in [" +
               formatNumber(lo.y()) + ", " + formatNumber(hi.y()) + "]",
           "Move the notch onto the sheet.");
}

sim::Notch readNotch(const TableReader& t, const sim::SheetParams& sheet) {
    if (!t.has("points")) t.missing("points", "at least 2 points");
    sim::Notch notch;
    notch.points = *t.points("points", 2);
    for (std::size_t i = 1; i < notch.points.size(); ++i) {
        if (notch.points[i] == notch.points[i - 1]) {
            const Eigen::Vector2d& p = notch.points[i];
            t.fail(
                "points",
                "consecutive points that differ (" + std::string(t.param("points").meaning) + ")",
                "point " + std::to_string(i) + " repeating [" + formatNumber(p.x()) + ", " +
                    formatNumber(p.y()) + "]",
                "Remove the repeated point.");
        }
    }
    checkNotchMeetsSheet(t, notch, sheet);
    return notch;
}

std::vector<sim::Notch> readNotches(const TableReader& root, const sim::SheetParams& sheet) {
    std::vector<sim::Notch> notches;
    for (const TableReader& t : root.entries("notch")) notches.push_back(readNotch(t, sheet));
    return notches;
}

// ---- [diffusion] -----------------------------------------------------------------------------

/// A spot whose disc misses the sheet's rest bounding box would silently do nothing.
void checkSpotReachesSheet(const TableReader& t, const sim::DiffusionSpot& s,
                           const sim::SheetParams& sheet) {
    const SheetExtent e = extentOf(sheet);
    const Eigen::Vector2d nearest = s.center.cwiseMax(e.min).cwiseMin(e.max);
    const double distance = (s.center - nearest).norm();
    if (distance <= s.radius) return;
    t.fail("center",
           "a centre within radius = " + formatNumber(s.radius) +
               " m of the sheet, whose rest extent is x in [" + formatNumber(e.min.x()) + ", " +
               formatNumber(e.max.x()) + "], y in [" + formatNumber(e.min.y()) + ", " +
               formatNumber(e.max.y()) + "]",
           "[" + formatNumber(s.center.x()) + ", " + formatNumber(s.center.y()) + "], " +
               formatNumber(distance) + " m away",
           "Move the spot onto the sheet or enlarge its radius.");
}

sim::DiffusionSpot readSpot(const TableReader& t, const sim::SheetParams& sheet) {
    sim::DiffusionSpot s;
    if (!t.has("center")) t.missing("center", "2 numbers");
    s.center = *t.vec2("center");
    s.radius = t.requiredNumber("radius");
    s.rate = t.requiredNumber("rate");
    s.start = t.number("start").value_or(s.start);
    s.duration = t.number("duration").value_or(s.duration);
    checkSpotReachesSheet(t, s, sheet);
    return s;
}

sim::SpotScatter readScatter(const TableReader& t) {
    sim::SpotScatter s;
    if (!t.has("count")) t.missing("count", "an integer " + t.param("count").range.describe());
    s.count = int(*t.integer("count"));
    s.radius = t.requiredNumber("radius");
    s.rate = t.requiredNumber("rate");
    s.start = t.number("start").value_or(s.start);
    s.spread = t.number("spread").value_or(s.spread);
    s.duration = t.number("duration").value_or(s.duration);
    s.seed = std::uint64_t(t.integer("seed").value_or(s.seed));
    return s;
}

sim::DiffusionEdge readDiffusionEdge(const TableReader& t, const Scene& scene) {
    sim::DiffusionEdge e;
    e.region = readRegion(t, scene);
    e.value = t.requiredNumber("value");
    return e;
}

sim::DiffusionParams readDiffusion(const TableReader& root, const Scene& scene) {
    const sim::SheetParams& sheet = scene.sim.sheet;
    const TableReader t = root.section("diffusion");
    sim::DiffusionParams d;
    d.initial = t.number("initial").value_or(d.initial);
    for (const TableReader& spot : t.entries("spot")) d.spots.push_back(readSpot(spot, sheet));
    double scattered = 0;
    for (const TableReader& scatter : t.entries("scatter")) {
        d.scatters.push_back(readScatter(scatter));
        scattered += d.scatters.back().count;
        if (scattered > kMaxScatteredSpots) {
            scatter.fail("count", "at most 1e5 scattered spots in all [[diffusion.scatter]]",
                         formatNumber(scattered) + " so far", "Lower count, or merge the entries.");
        }
    }
    for (const TableReader& edge : t.entries("edge"))
        d.edges.push_back(readDiffusionEdge(edge, scene));
    return d;
}

// ---- [forces], [time] ------------------------------------------------------------------------

void readForces(const TableReader& root, sim::MembraneParams& p) {
    const TableReader t = root.section("forces");
    p.gravity = t.vec3("gravity").value_or(p.gravity);
    p.damping = t.number("damping").value_or(p.damping);
    p.pressure = t.number("pressure").value_or(p.pressure);
}

void readMpm(const TableReader& root, sim::MpmParams& mpm) {
    const TableReader t = root.section("mpm");
    mpm.grid = t.number("grid").value_or(mpm.grid);
    mpm.enrich = t.boolean("enrich").value_or(mpm.enrich);
}

void readRemesh(const TableReader& root, sim::RemeshParams& remesh) {
    const TableReader t = root.section("remesh");
    if (const auto every = t.integer("every")) remesh.every = int(*every);
}

void readTime(const TableReader& root, Scene& scene) {
    const TableReader t = root.section("time");
    sim::TimeParams& time = scene.sim.time;
    time.dt = t.numberOrWord("dt", time.dt);
    if (const toml::node* dt = t.find("dt"); dt && dt->as_string())
        time.control =
            dt->as_string()->get() == "auto" ? sim::StepControl::Auto : sim::StepControl::Adaptive;
    time.safety = t.number("safety").value_or(time.safety);
    time.maxStretchIncrement = t.number("max_stretch_increment").value_or(time.maxStretchIncrement);
    time.burstBonds = int(t.integer("burst_bonds").value_or(time.burstBonds));
    time.duration = t.number("duration").value_or(time.duration);
    time.fps = t.number("fps").value_or(time.fps);
    time.allowUnstable = t.boolean("allow_unstable").value_or(time.allowUnstable);
    scene.allowSlow = t.boolean("allow_slow").value_or(scene.allowSlow);
    time.integrator =
        sim::Integrator(t.choice("integrator").value_or(std::size_t(time.integrator)));
    // Frame k shows t = k / fps: with no whole frame inside duration, the one frame written
    // would simulate past it (1e3 s for fps = 1e-3).
    if (time.duration * time.fps < 0.5) {
        t.fail(t.has("fps") ? "fps" : "duration", "at least one frame (duration * fps >= 0.5)",
               formatNumber(time.duration * time.fps) + " frames",
               "Raise fps or lengthen duration.");
    }
    if (time.duration * time.fps > kMaxFrames) {
        t.fail(t.has("duration") ? "duration" : "fps", "at most 1e6 frames (duration * fps)",
               formatNumber(std::round(time.duration * time.fps)) + " frames",
               "Shorten duration or lower fps.");
    }
}

// ---- [camera], [light], [render], [output] ---------------------------------------------------

/// Without a camera the sheet is framed from the front and above, far enough to see it whole.
render::Camera defaultCamera(const sim::SheetParams& sheet) {
    const double extent = extentOf(sheet).largest;
    render::Camera c;
    c.lookAt = sheet.center;
    c.position = sheet.center + extent * Eigen::Vector3d(0.0, -1.6, 1.25);
    c.up = Eigen::Vector3d(0, 0, 1);
    c.fovYDegrees = 40.0;
    return c;
}

render::Camera readCamera(const TableReader& root, const sim::SheetParams& sheet) {
    const TableReader t = root.section("camera");
    render::Camera c = defaultCamera(sheet);
    c.position = t.vec3("position").value_or(c.position);
    c.lookAt = t.vec3("look_at").value_or(c.lookAt);
    c.up = t.vec3("up", true).value_or(c.up);
    c.fovYDegrees = t.number("fov").value_or(c.fovYDegrees);

    const Eigen::Vector3d view = c.lookAt - c.position;
    if (view.norm() == 0.0) {
        t.fail(t.has("position") ? "position" : "look_at", "a position different from look_at",
               "both at the same point", "Move the camera away from the point it looks at.");
    }
    if (view.normalized().cross(c.up.normalized()).norm() < 1e-6) {
        t.fail(t.has("up") ? "up" : "position",
               "an up direction not parallel to the view direction (look_at - position)",
               "them parallel", "Use e.g. up = [0.0, 0.0, 1.0] with a camera not straight above.");
    }
    return c;
}

void readLight(const TableReader& root, render::RenderSettings& r) {
    const TableReader t = root.section("light");
    r.sun.direction = t.vec3("direction", true).value_or(r.sun.direction);
    r.sun.color = t.vec3("color").value_or(r.sun.color);
    r.sun.intensity = t.number("intensity").value_or(r.sun.intensity);
    r.ambient = t.number("ambient").value_or(r.ambient);
}

std::optional<std::array<double, 2>> readColorRange(const TableReader& t) {
    const std::optional<Eigen::Vector2d> range = t.vec2("color_range");
    if (!range) return std::nullopt;
    if (range->x() >= range->y()) {
        t.fail("color_range",
               "[lo, hi] with lo < hi (" + std::string(t.param("color_range").meaning) + ")",
               "[" + formatNumber(range->x()) + ", " + formatNumber(range->y()) + "]",
               t.useInstead("color_range"));
    }
    return std::array<double, 2>{range->x(), range->y()};
}

void readImage(const TableReader& t, Scene& scene) {
    render::RenderSettings& r = scene.render;
    scene.renderer = RendererKind(t.choice("renderer").value_or(0));
    r.width = int(t.integer("width").value_or(r.width));
    r.height = int(t.integer("height").value_or(r.height));
    r.supersample = int(t.integer("supersample").value_or(r.supersample));
    r.colorBy = render::ColorBy(t.choice("color_by").value_or(std::size_t(r.colorBy)));
    r.colorRange = readColorRange(t);
    r.thetaStyle = render::ThetaStyle(t.choice("theta_style").value_or(std::size_t(r.thetaStyle)));
    r.tone.curve = render::ToneCurve(t.choice("tone_map").value_or(std::size_t(r.tone.curve)));
    r.tone.exposure = t.number("exposure").value_or(r.tone.exposure);
}

/// A look is a preset: it sets the material keys' defaults, which the scene's own keys
/// (read after it) override one by one.
void readLook(const TableReader& t, render::RenderSettings& r) {
    r.look = render::Look(t.choice("look").value_or(std::size_t(r.look)));
    if (r.look != render::Look::Plain) render::applyLookPreset(r);
}

void readPathTracing(const TableReader& t, render::PathTracing& p) {
    p.samplesPerPixel = int(t.integer("spp").value_or(p.samplesPerPixel));
    p.maxDepth = int(t.integer("max_depth").value_or(p.maxDepth));
    p.denoise = t.boolean("denoise").value_or(p.denoise);
    p.material = render::MaterialKind(t.choice("material").value_or(std::size_t(p.material)));
    p.roughness = t.number("roughness").value_or(p.roughness);
    p.transmission = t.number("transmission").value_or(p.transmission);
    p.sky = t.boolean("sky").value_or(p.sky);
    p.sunAngularRadiusDegrees = t.number("sun_radius").value_or(p.sunAngularRadiusDegrees);
    p.skyZenith = t.vec3("sky_zenith").value_or(p.skyZenith);
    p.skyHorizon = t.vec3("sky_horizon").value_or(p.skyHorizon);
}

/// A voxel far below dx or a particle radius far above it makes the level set's grid huge.
void checkVdbSizes(const TableReader& t, const render::VdbSettings& v, double dx) {
    if (v.voxelSize != 0.0 && v.voxelSize < dx / 16) {
        t.fail("vdb_voxel_size", "0 (dx / 2) or at least dx / 16 = " + formatNumber(dx / 16) + " m",
               formatNumber(v.voxelSize),
               "Use e.g. vdb_voxel_size = " + formatNumber(dx / 2) + ".");
    }
    if (v.particleRadius > 16 * dx) {
        t.fail("vdb_particle_radius",
               "0 (0.75 dx) or at most 16 dx = " + formatNumber(16 * dx) + " m",
               formatNumber(v.particleRadius),
               "Use e.g. vdb_particle_radius = " + formatNumber(0.75 * dx) + ".");
    }
}

void readSurface(const TableReader& t, render::RenderSettings& r, double dx) {
    r.surface = render::SurfaceKind(t.choice("surface").value_or(std::size_t(r.surface)));
    r.thickness = t.number("thickness").value_or(r.thickness);
    r.vdb.voxelSize = t.number("vdb_voxel_size").value_or(r.vdb.voxelSize);
    r.vdb.particleRadius = t.number("vdb_particle_radius").value_or(r.vdb.particleRadius);
    r.vdb.smoothingIterations = int(t.integer("vdb_smoothing").value_or(r.vdb.smoothingIterations));
    r.vdb.adaptivity = t.number("vdb_adaptivity").value_or(r.vdb.adaptivity);
    checkVdbSizes(t, r.vdb, dx);
}

void readRender(const TableReader& root, const sim::SheetParams& sheet, Scene& scene) {
    const TableReader t = root.section("render");
    render::RenderSettings& r = scene.render;
    readImage(t, scene);
    readLook(t, r);
    readPathTracing(t, r.pathTracing);
    readSurface(t, r, sheet.dx);
    r.albedo = t.vec3("albedo").value_or(r.albedo);
    r.background = t.vec3("background").value_or(r.background);
    r.groundColor = t.vec3("ground_color").value_or(r.groundColor);
    r.ground = t.boolean("ground").value_or(r.ground);
    // Half the sheet's size below it: out of the way of sagging, still in the picture.
    const double belowSheet = sheet.center.z() - 0.5 * extentOf(sheet).largest;
    r.groundHeight = t.number("ground_height").value_or(belowSheet);
}

void readOutput(const TableReader& root, Scene& scene) {
    const TableReader t = root.section("output");
    scene.writeStats = t.boolean("stats").value_or(scene.writeStats);
    scene.writeExr = t.boolean("exr").value_or(scene.writeExr);
    const toml::node* list = t.find("export");
    if (!list) return;
    const std::span<const std::string_view> formats = t.param("export").names;
    const std::string expected = "an array of format names, " + scene::oneOf(formats);
    const toml::array* array = list->as_array();
    if (!array) t.fail("export", expected, scene::describeType(*list), t.useInstead("export"));
    for (const toml::node& item : *array) {
        const auto name = item.value<std::string>();
        const auto index = name ? names::indexOf(formats, *name) : std::nullopt;
        if (!index) t.fail("export", expected, scene::describeType(item), t.useInstead("export"));
        scene.exports.push_back(ExportFormat(*index));
    }
}

// `solver = "..."` at the top level: a name from the solver registry (sim/SolverRegistry.h),
// which also says what each solver takes. A scene asking for what its solver lacks is refused,
// not silently run without.
void readSolver(const TableReader& root, sim::MembraneParams& p) {
    const scene::Param& kSolver = root.param("solver");
    if (const auto k = root.choice(kSolver.key)) p.solver = std::string(kSolver.names[*k]);
    const std::string needs = sim::unsupportedFeatures(sim::solverEntry(p.solver), p);
    if (needs.empty()) return;
    root.fail(kSolver.key, "a solver that takes " + needs, "\"" + p.solver + "\"",
              "The " + p.solver + " solver does not take " + needs +
                  "; remove it or use solver = \"peridynamic\" (README \"Solvers\" lists what "
                  "each takes).");
}

std::string toJson(const toml::table& document) {
    std::ostringstream out;
    out << toml::json_formatter{document};
    return out.str();
}

/// FNV-1a of the resolved scene's JSON without the tables that only shape the pictures.
std::uint64_t simulationFingerprint(toml::table document) {
    for (const char* pictureOnly : {"render", "camera", "light", "output"})
        document.erase(pictureOnly);
    std::uint64_t h = 0xcbf29ce484222325ULL;
    for (const unsigned char c : toJson(document)) h = (h ^ c) * 0x100000001b3ULL;
    return h;
}

/// Lattice points per dx^2: 2/sqrt(3) on the hexagonal lattice, 1 on the square one. The
/// sphere's geodesic grid measured 2.04 (2562 particles for r = 1 m, dx = 0.1 m).
double particlesPerCell(const sim::SheetParams& sheet) {
    if (sheet.outline == sim::Outline::Sphere) return 2.1;
    return sheet.lattice == sim::LatticeKind::Square ? 1.0 : 2.0 / std::sqrt(3.0);
}

}  // namespace

SheetEstimate estimateSheet(const sim::SheetParams& sheet) {
    SheetEstimate e;
    const double density = particlesPerCell(sheet);
    e.particles = extentOf(sheet).area / (sheet.dx * sheet.dx) * density;
    // Lattice points within R = horizon * dx, the particle itself excluded; never fewer than the
    // nearest-neighbour ring that every solver's mesh has.
    const double r = sheet.horizonFactor;
    e.bondsPerParticle = std::max(6.0, std::numbers::pi * r * r * density - 1.0);
    e.bytes = e.particles * (SheetEstimate::kBytesPerParticle +
                             e.bondsPerParticle * SheetEstimate::kBytesPerBondEnd);
    return e;
}

int Scene::frameCount() const {
    return std::max(1, int(std::lround(sim.time.duration * sim.time.fps)));
}

std::string Scene::locationOf(std::string_view key) const {
    // The key itself, else its nearest enclosing table that the file gave, else the file.
    for (std::string path(key);; path.resize(path.rfind('.'))) {
        if (const auto it = locations.find(path); it != locations.end() && !it->second.empty())
            return it->second;
        if (path.find('.') == std::string::npos) break;
    }
    const auto root = locations.find("");
    return root != locations.end() && !root->second.empty() ? root->second : file.string();
}

std::filesystem::path assetsDirectory() {
    const char* env = std::getenv("REND_ASSETS");
    if (env && *env) return env;
    return REND_DEFAULT_ASSETS_DIR;
}

Scene loadScene(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
    const toml::table document = scene::buildSceneDocument(file, overrides, assetsDirectory());
    scene::KeyLog log;
    const TableReader root(document, scene::sectionAt(""), "", "the top-level table", log,
                           file.string());
    Scene s;
    s.file = file;
    s.overrides = overrides;
    readSheet(root, s);
    s.sim.material = readMaterial(root);
    readMaterialMaps(root, s);
    s.sim.boundaries = readBoundaries(root, s);
    s.sim.notches = readNotches(root, s.sim.sheet);
    s.sim.diffusion = readDiffusion(root, s);
    readForces(root, s.sim);
    readMpm(root, s.sim.mpm);
    readRemesh(root, s.sim.remesh);
    readSolver(root, s.sim);
    readTime(root, s);
    s.render.camera = readCamera(root, s.sim.sheet);
    readLight(root, s.render);
    readRender(root, s.sim.sheet, s);
    readContact(root, s);
    readOutput(root, s);
    log.reportUnused();
    s.locations = log.locations();
    s.resolvedJson = toJson(document);
    s.simulationFingerprint = simulationFingerprint(document);
    return s;
}

}  // namespace rend
