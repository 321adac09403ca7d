// Scene schema: every key, its range, its default and an example live here, next to each other,
// and every value is checked once, at load. Unknown keys are errors, never warnings.

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <sstream>

#include "app/Scene.h"
#include "app/SceneDocument.h"
#include "app/SceneError.h"
#include "app/SceneReader.h"
#include "sim/SolverRegistry.h"

namespace rend {
namespace {

using scene::formatNumber;
using scene::Param;
using scene::Range;
using scene::TableReader;

// Each list follows its enum's order, so a choice's index converts straight to the enum.
constexpr std::string_view kShapes[] = {"rectangle", "disc", "sphere"};
constexpr std::string_view kLattices[] = {"hexagonal", "square"};
constexpr std::string_view kMicromoduli[] = {"calibrated", "paper"};
constexpr std::string_view kBoundaryTypes[] = {"velocity", "pinned"};
enum class Edge { Left, Right, Bottom, Top };
constexpr std::string_view kEdges[] = {"left", "right", "bottom", "top"};
constexpr std::string_view kRenderers[] = {"osmesa", "none", "embree"};
constexpr std::string_view kSurfaces[] = {"lattice", "splat", "vdb"};
constexpr std::string_view kMaterials[] = {"diffuse", "conductor", "film", "translucent"};
constexpr std::string_view kExportFormats[] = {"ply", "obj", "glb", "vdb"};
constexpr std::string_view kColorModes[] = {"none", "speed", "strain", "theta", "damage"};

/// Above this the lattice alone needs gigabytes and a frame takes minutes.
constexpr double kMaxParticles = 5e6;
/// Fewer particles across than this cannot bend or stretch in any meaningful way.
constexpr double kMinParticlesAcross = 4;
/// Guards frameCount() against int overflow; ~11 hours of video at 24 fps.
constexpr double kMaxFrames = 1e6;

std::string sectionFix(std::string_view name) {
    return "Write it as a table: a [" + std::string(name) + "] header followed by its keys.";
}

/// Two significant digits, so limits and suggestions read like something a person would type;
/// `direction` (-1, 0, +1) rounds down, to nearest or up, to keep a quoted limit valid.
double roundForDisplay(double value, int direction = 0) {
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
    constexpr Param kShape{"shape", "the sheet's outline", "\"rectangle\""};
    constexpr Param kSize{"size", "the rectangle's extent [x, y] in metres", "[2.0, 2.0]"};
    constexpr Param kRadius{"radius", "the disc or sphere radius in metres", "1.0"};
    s.outline = sim::Outline(t.choice(kShape, kShapes).value_or(0));
    if (s.outline == sim::Outline::Rectangle) {
        if (!t.has(kSize.key)) t.missing(kSize, "2 numbers > 0");
        s.size = *t.vec2(kSize, Range::positive());
        rejectForShape(t, kRadius.key, "rectangle", "Remove radius, or set shape = \"disc\".");
    } else {
        s.radius = t.requiredNumber(kRadius, Range::positive());
        rejectForShape(t, kSize.key, kShapes[std::size_t(s.outline)],
                       "Remove size and give radius instead.");
    }
}

/// dx is bounded by the outline on both sides: coarse enough to fit the particle budget, fine
/// enough to resolve the sheet at all.
void checkSpacing(const TableReader& t, const sim::SheetParams& s) {
    const SheetExtent e = extentOf(s);
    const double maxDx = e.smallest / (kMinParticlesAcross - 1);
    if (s.dx > maxDx) {
        t.fail("dx",
               "a spacing of at most " + formatNumber(roundForDisplay(maxDx, -1)) +
                   " m, so that at least 4 particles fit "
                   "across the sheet's smaller extent of " +
                   formatNumber(e.smallest) + " m",
               formatNumber(s.dx),
               "Use e.g. dx = " + formatNumber(roundForDisplay(e.smallest / 50)) + ".");
    }
    const double estimate = e.area / (s.dx * s.dx);
    if (estimate > kMaxParticles) {
        const double minDx = std::sqrt(e.area / kMaxParticles);
        t.fail("dx",
               "a spacing of at least " + formatNumber(roundForDisplay(minDx, +1)) +
                   " m, so that the sheet has at most 5e6 particles (area / dx^2)",
               formatNumber(s.dx) + ", about " + formatNumber(std::round(estimate)) + " particles",
               "Use e.g. dx = " + formatNumber(roundForDisplay(minDx * 2)) + ".");
    }
}

sim::SheetParams readSheet(const TableReader& root) {
    constexpr Param kSheet{"sheet", "the membrane's outline and lattice", ""};
    const TableReader t = root.section(kSheet, "[sheet]",
                                       {"shape", "size", "radius", "center", "lattice", "dx",
                                        "horizon", "thickness", "perturbation", "seed"},
                                       sectionFix("sheet"));
    constexpr Param kDx{"dx", "the particle spacing in metres", "0.02"};
    constexpr Param kCenter{"center", "the sheet's centre [x, y, z] in metres", "[0.0, 0.0, 0.0]"};
    constexpr Param kLattice{"lattice", "the particle arrangement", "\"hexagonal\""};
    constexpr Param kHorizon{"horizon", "the bond cutoff in units of dx", "1.5"};
    constexpr Param kThickness{"thickness", "the membrane thickness in metres", "0.001"};
    constexpr Param kPerturbation{"perturbation", "the out-of-plane jitter amplitude in metres",
                                  "1e-4"};
    constexpr Param kSeed{"seed", "the jitter's random seed", "7"};

    sim::SheetParams s;
    s.dx = t.requiredNumber(kDx, Range::positive());
    readOutline(t, s);
    s.center = t.vec3(kCenter).value_or(s.center);
    s.lattice = sim::LatticeKind(t.choice(kLattice, kLattices).value_or(std::size_t(s.lattice)));
    s.horizonFactor = t.number(kHorizon, Range::openClosed(1.0, 6.0)).value_or(s.horizonFactor);
    s.thickness = t.number(kThickness, Range::positive()).value_or(s.thickness);
    s.perturbationAmplitude =
        t.number(kPerturbation, Range::nonNegative()).value_or(s.perturbationAmplitude);
    s.perturbationSeed =
        std::uint64_t(t.integer(kSeed, Range::nonNegative()).value_or(s.perturbationSeed));
    checkSpacing(t, s);
    return s;
}

// ---- [material] ------------------------------------------------------------------------------

constexpr std::string_view kLaws[] = {"linear", "power_law", "elastoplastic"};
constexpr std::string_view kCriticalStretches[] = {"calibrated", "paper"};

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
    constexpr Param kLaw{"law", "the bond law: eq. 18, 19 or 20 of the membrane paper",
                         "\"linear\""};
    constexpr Param kPowerRatio{"power_ratio", "c*/c of the power law, eq. 19", "-0.1"};
    constexpr Param kPowerExponent{"power_exponent", "the exponent n of the power law, eq. 19",
                                   "4"};
    // Table 1 lists eta0 for every material; only the elastoplastic law (eqs. 20, 27) uses it.
    constexpr Param kYieldStrain{"yield_strain", "the elastic limit eta0 of eqs. 20 and 27",
                                 "1e-4"};
    constexpr Param kSoftening{"softening", "beta of eqs. 20 and 27, the post-yield decay", "1.0"};

    requireSwitch(t, kPowerRatio.key, kLaw.key, "it belongs to law = \"power_law\"",
                  "Add law = \"power_law\", or remove power_ratio.");
    requireSwitch(t, kPowerExponent.key, kLaw.key, "it belongs to law = \"power_law\"",
                  "Add law = \"power_law\", or remove power_exponent.");
    requireSwitch(t, kSoftening.key, kLaw.key, "it belongs to law = \"elastoplastic\"",
                  "Add law = \"elastoplastic\", or remove softening.");
    m.law = sim::BondLawKind(t.choice(kLaw, kLaws).value_or(std::size_t(m.law)));
    m.powerLawRatio = t.number(kPowerRatio, Range::atMost(0.0)).value_or(m.powerLawRatio);
    m.powerLawExponent = t.number(kPowerExponent, Range::above(1.0)).value_or(m.powerLawExponent);
    m.yieldStrain = t.number(kYieldStrain, Range::positive()).value_or(m.yieldStrain);
    m.softening = t.number(kSoftening, Range::positive()).value_or(m.softening);
}

/// fracture_energy is a number, or "none" for an unbreakable sheet (the default), so that a
/// preset's fracture can be switched off with --set material.fracture_energy=none.
void readFracture(const TableReader& t, sim::MaterialParams& m) {
    constexpr Param kFractureEnergy{"fracture_energy", "the fracture energy G_f in J/m^2", "11.3"};
    constexpr Param kCriticalStretch{"critical_stretch",
                                     "how the critical stretch follows from G_f", "\"calibrated\""};
    constexpr Param kStrengthLoss{
        "strength_loss", "the critical stretch lost per unit theta (acid, moisture)", "0.6"};
    requireSwitch(t, kCriticalStretch.key, kFractureEnergy.key, "bonds never break without it",
                  "Add e.g. fracture_energy = 11.3, or remove critical_stretch.");
    requireSwitch(t, kStrengthLoss.key, kFractureEnergy.key, "bonds never break without it",
                  "Add e.g. fracture_energy = 11.3, or remove strength_loss.");
    if (const toml::node* node = t.find(kFractureEnergy.key)) {
        if (const auto* text = node->as_string(); text && text->get() == "none") {
            m.fractureEnergy.reset();
        } else if (node->is_number()) {
            m.fractureEnergy = t.number(kFractureEnergy, Range::positive());
        } else {
            t.fail(kFractureEnergy.key,
                   "a number > 0 (the fracture energy G_f in J/m^2) or \"none\" (unbreakable)",
                   scene::describeType(*node),
                   "Use e.g. fracture_energy = 11.3 or fracture_energy = \"none\".");
        }
    }
    m.criticalStretch = sim::CriticalStretchMode(
        t.choice(kCriticalStretch, kCriticalStretches).value_or(std::size_t(m.criticalStretch)));
    m.strengthLoss = t.number(kStrengthLoss, Range::nonNegative()).value_or(m.strengthLoss);
    constexpr Param kSurfaceCorrection{
        "surface_correction", "whether edge particles are stiffened to the interior's", "true"};
    m.surfaceCorrection = t.boolean(kSurfaceCorrection).value_or(m.surfaceCorrection);
}

/// The diffusive quantity theta inside the material (eq. 25) and what it does to it.
void readDiffusivity(const TableReader& t, sim::MaterialParams& m) {
    constexpr Param kCapacity{"capacity", "the diffusive capacity C of eq. 25", "1.0"};
    constexpr Param kConductivity{"conductivity", "the coefficient of diffusion k of eq. 25",
                                  "0.01"};
    constexpr Param kExpansion{"expansion", "alpha, the strain per unit theta", "0.3"};
    constexpr Param kStiffnessLoss{"stiffness_loss", "the stiffness lost per unit theta", "0.5"};
    m.capacity = t.number(kCapacity, Range::positive()).value_or(m.capacity);
    m.conductivity = t.number(kConductivity, Range::nonNegative()).value_or(m.conductivity);
    m.expansion = t.number(kExpansion, Range::any()).value_or(m.expansion);
    m.stiffnessLoss = t.number(kStiffnessLoss, Range::nonNegative()).value_or(m.stiffnessLoss);
}

sim::MaterialParams readMaterial(const TableReader& root) {
    constexpr Param kMaterial{"material", "the membrane's material", ""};
    const TableReader t =
        root.section(kMaterial, "[material]",
                     {"preset", "name", "E", "poisson", "density", "micromodulus", "law",
                      "power_ratio", "power_exponent", "yield_strain", "softening",
                      "fracture_energy", "critical_stretch", "capacity", "conductivity",
                      "expansion", "stiffness_loss", "strength_loss", "surface_correction"},
                     sectionFix("material"));
    constexpr Param kPreset{"preset", "a file name under assets/materials without .toml",
                            "\"stretch_sheet\""};
    constexpr Param kName{"name", "the material's name", "\"rubber\""};
    constexpr Param kE{"E", "Young's modulus in Pa", "2e4"};
    constexpr Param kPoisson{"poisson", "Poisson's ratio", "0.3"};
    constexpr Param kDensity{"density", "the density in kg/m^3", "5000"};
    constexpr Param kMicromodulus{"micromodulus", "how the bond stiffness is derived",
                                  "\"calibrated\""};

    sim::MaterialParams m;
    const std::optional<std::string> preset = t.string(kPreset);  // merged already; type-check
    m.name = t.string(kName).value_or(preset.value_or(m.name));
    m.youngsModulus = t.requiredNumber(kE, Range::positive());
    m.poissonRatio = t.number(kPoisson, Range::open(-1.0, 0.5)).value_or(m.poissonRatio);
    m.density = t.requiredNumber(kDensity, Range::positive());
    m.micromodulus = sim::MicromodulusMode(
        t.choice(kMicromodulus, kMicromoduli).value_or(std::size_t(m.micromodulus)));
    readBondLaw(t, m);
    readFracture(t, m);
    readDiffusivity(t, m);
    return m;
}

// ---- [[boundary]] ----------------------------------------------------------------------------

constexpr Param kEdge{"edge",
                      "the region: edge = \"left\" | \"right\" | \"bottom\" | \"top\", or box = "
                      "{ min = [x, y], max = [x, y] }",
                      "\"left\""};
constexpr Param kBox{"box", "the region's corners in rest coordinates",
                     "{ min = [-1.0, -1.0], max = [-0.9, 1.0] }"};
constexpr Param kDepth{"depth", "the strip width in units of dx", "1.0"};

/// The strip of width depth*dx along one side of the sheet's rest bounding box. The outer
/// side stays unbounded and the inner one gets a hair of tolerance, so the particles exactly on
/// the strip's edges are included despite rounding in the lattice.
sim::Region edgeRegion(Edge edge, double depth, const sim::SheetParams& sheet) {
    const SheetExtent e = extentOf(sheet);
    const double width = depth * sheet.dx + 1e-9 * sheet.dx;
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
    constexpr Param kMin{"min", "the box's lower corner [x, y] in metres", "[-1.0, -1.0]"};
    constexpr Param kMax{"max", "the box's upper corner [x, y] in metres", "[-0.9, 1.0]"};
    const TableReader box =
        *t.subtable(kBox, t.keyPath("box"), {"min", "max"}, TableReader::useInstead(kBox));
    if (!box.has(kMin.key)) box.missing(kMin, "");
    if (!box.has(kMax.key)) box.missing(kMax, "");
    sim::Region r;
    r.min = *box.vec2(kMin);
    r.max = *box.vec2(kMax);
    if ((r.min.array() >= r.max.array()).any()) {
        t.fail("box", "min < max in both x and y (" + std::string(kBox.meaning) + ")",
               "min = [" + formatNumber(r.min.x()) + ", " + formatNumber(r.min.y()) + "], max = [" +
                   formatNumber(r.max.x()) + ", " + formatNumber(r.max.y()) + "]",
               "Swap the offending coordinates.");
    }
    return r;
}

sim::Region readRegion(const TableReader& t, const sim::SheetParams& sheet) {
    if (t.has("edge") && t.has("box")) {
        t.fail("box", "either edge or box, not both", "both", "Remove edge or box.");
    }
    if (t.has("box")) {
        if (t.has("depth")) {
            t.fail("depth", "no depth with box (depth applies to edge regions)",
                   scene::describeType(*t.find("depth")),
                   "Remove depth, or use edge instead of box.");
        }
        return boxRegion(t);
    }
    if (!t.has("edge")) t.missing(kEdge, "");
    const Edge edge = Edge(*t.choice(kEdge, kEdges));
    return edgeRegion(edge, t.number(kDepth, Range::positive()).value_or(1.0), sheet);
}

/// Keys that only a velocity condition uses are errors on a pinned one, not silently ignored.
void rejectForPinned(const TableReader& t, std::string_view key) {
    if (const toml::node* node = t.find(key)) {
        t.fail(key, "no " + std::string(key) + " for type = \"pinned\"", scene::describeType(*node),
               "Remove " + std::string(key) + ", or set type = \"velocity\".");
    }
}

sim::BoundaryCondition readBoundary(const toml::table& table, std::size_t index,
                                    const sim::SheetParams& sheet) {
    const std::string path = "boundary." + std::to_string(index);
    const TableReader t(table, path, "[[boundary]] entry " + std::to_string(index),
                        {"type", "edge", "depth", "box", "velocity", "ramp"});
    constexpr Param kType{"type", "the kind of condition", "\"velocity\""};
    constexpr Param kVelocity{"velocity", "the prescribed velocity [x, y, z] in m/s",
                              "[0.15, 0.0, 0.0]"};
    constexpr Param kRamp{"ramp", "seconds to reach full speed from rest", "0.5"};

    sim::BoundaryCondition bc;
    if (!t.has(kType.key)) t.missing(kType, "one of \"velocity\", \"pinned\"");
    bc.kind = sim::BoundaryKind(*t.choice(kType, kBoundaryTypes));
    bc.region = readRegion(t, sheet);
    if (bc.kind == sim::BoundaryKind::Pinned) {
        rejectForPinned(t, kVelocity.key);
        rejectForPinned(t, kRamp.key);
        return bc;
    }
    if (!t.has(kVelocity.key)) t.missing(kVelocity, "");
    bc.velocity = *t.vec3(kVelocity);
    bc.rampTime = t.number(kRamp, Range::nonNegative()).value_or(bc.rampTime);
    return bc;
}

/// The tables of an array of tables such as [[boundary]]; absent reads as none.
std::vector<const toml::table*> tablesOf(const TableReader& parent, std::string_view key,
                                         std::string_view header) {
    const toml::node* node = parent.find(key);
    if (!node) return {};
    const std::string expected = "an array of tables written as [[" + std::string(header) + "]]";
    const std::string fix = "Give each entry its own [[" + std::string(header) + "]] header.";
    const toml::array* array = node->as_array();
    if (!array) parent.fail(key, expected, scene::describeType(*node), fix);
    std::vector<const toml::table*> tables;
    for (const toml::node& item : *array) {
        const toml::table* table = item.as_table();
        if (!table) {
            parent.fail(key, expected, "an array containing " + scene::describeType(item), fix);
        }
        tables.push_back(table);
    }
    return tables;
}

std::vector<sim::BoundaryCondition> readBoundaries(const TableReader& root,
                                                   const sim::SheetParams& sheet) {
    std::vector<sim::BoundaryCondition> conditions;
    for (const toml::table* table : tablesOf(root, "boundary", "boundary")) {
        conditions.push_back(readBoundary(*table, conditions.size(), sheet));
    }
    return conditions;
}

// ---- [[notch]] -------------------------------------------------------------------------------

sim::Notch readNotch(const toml::table& table, std::size_t index) {
    const TableReader t(table, "notch." + std::to_string(index),
                        "[[notch]] entry " + std::to_string(index), {"points"});
    constexpr Param kPoints{"points", "the notch polyline in rest coordinates, metres",
                            "[[-1.0, 0.0], [-0.6, 0.0]]"};
    if (!t.has(kPoints.key)) t.missing(kPoints, "at least 2 points");
    sim::Notch notch;
    notch.points = *t.points(kPoints, 2);
    for (std::size_t i = 1; i < notch.points.size(); ++i) {
        if (notch.points[i] == notch.points[i - 1]) {
            const Eigen::Vector2d& p = notch.points[i];
            t.fail(kPoints.key,
                   "consecutive points that differ (" + std::string(kPoints.meaning) + ")",
                   "point " + std::to_string(i) + " repeating [" + formatNumber(p.x()) + ", " +
                       formatNumber(p.y()) + "]",
                   "Remove the repeated point.");
        }
    }
    return notch;
}

std::vector<sim::Notch> readNotches(const TableReader& root) {
    std::vector<sim::Notch> notches;
    for (const toml::table* table : tablesOf(root, "notch", "notch")) {
        notches.push_back(readNotch(*table, notches.size()));
    }
    return notches;
}

// ---- [diffusion] -----------------------------------------------------------------------------

constexpr Param kSourceRadius{"radius", "the source's radius in metres", "0.05"};
constexpr Param kSourceRate{"rate", "theta added per second inside it (negative: a sink)", "1.0"};
constexpr Param kSourceStart{"start", "the time in seconds it switches on", "0.0"};
constexpr Param kSourceDuration{"duration", "how many seconds it stays on (default: forever)",
                                "2.0"};

/// A spot whose disc misses the sheet's rest bounding box would silently do nothing.
void checkSpotReachesSheet(const TableReader& t, const Param& kCenter, const sim::DiffusionSpot& s,
                           const sim::SheetParams& sheet) {
    const SheetExtent e = extentOf(sheet);
    const Eigen::Vector2d nearest = s.center.cwiseMax(e.min).cwiseMin(e.max);
    const double distance = (s.center - nearest).norm();
    if (distance <= s.radius) return;
    t.fail(kCenter.key,
           "a centre within radius = " + formatNumber(s.radius) +
               " m of the sheet, whose rest extent is x in [" + formatNumber(e.min.x()) + ", " +
               formatNumber(e.max.x()) + "], y in [" + formatNumber(e.min.y()) + ", " +
               formatNumber(e.max.y()) + "]",
           "[" + formatNumber(s.center.x()) + ", " + formatNumber(s.center.y()) + "], " +
               formatNumber(distance) + " m away",
           "Move the spot onto the sheet or enlarge its radius.");
}

sim::DiffusionSpot readSpot(const toml::table& table, std::size_t index,
                            const sim::SheetParams& sheet) {
    const TableReader t(table, "diffusion.spot." + std::to_string(index),
                        "[[diffusion.spot]] entry " + std::to_string(index),
                        {"center", "radius", "rate", "start", "duration"});
    constexpr Param kCenter{"center", "the spot's centre [x, y] in rest coordinates, metres",
                            "[0.0, 0.0]"};
    sim::DiffusionSpot s;
    if (!t.has(kCenter.key)) t.missing(kCenter, "2 numbers");
    s.center = *t.vec2(kCenter);
    s.radius = t.requiredNumber(kSourceRadius, Range::positive());
    s.rate = t.requiredNumber(kSourceRate, Range::any());
    s.start = t.number(kSourceStart, Range::nonNegative()).value_or(s.start);
    s.duration = t.number(kSourceDuration, Range::positive()).value_or(s.duration);
    checkSpotReachesSheet(t, kCenter, s, sheet);
    return s;
}

/// Each scatter expands to `count` spots; the cap keeps set-up and the per-step source loop sane.
constexpr double kMaxScatterCount = 1e4;

sim::SpotScatter readScatter(const toml::table& table, std::size_t index) {
    const TableReader t(table, "diffusion.scatter." + std::to_string(index),
                        "[[diffusion.scatter]] entry " + std::to_string(index),
                        {"count", "radius", "rate", "start", "spread", "duration", "seed"});
    constexpr Param kCount{"count", "how many spots or droplets", "20"};
    constexpr Param kSpread{"spread",
                            "seconds over which droplets are emitted; 0: all spots at once", "3.0"};
    constexpr Param kSeed{"seed", "the placement's random seed", "1"};
    const Range countRange = Range::closed(1, kMaxScatterCount);
    sim::SpotScatter s;
    if (!t.has(kCount.key)) t.missing(kCount, "an integer " + countRange.describe());
    s.count = int(*t.integer(kCount, countRange));
    s.radius = t.requiredNumber(kSourceRadius, Range::positive());
    s.rate = t.requiredNumber(kSourceRate, Range::any());
    s.start = t.number(kSourceStart, Range::nonNegative()).value_or(s.start);
    s.spread = t.number(kSpread, Range::nonNegative()).value_or(s.spread);
    s.duration = t.number(kSourceDuration, Range::positive()).value_or(s.duration);
    s.seed = std::uint64_t(t.integer(kSeed, Range::nonNegative()).value_or(s.seed));
    return s;
}

sim::DiffusionEdge readDiffusionEdge(const toml::table& table, std::size_t index,
                                     const sim::SheetParams& sheet) {
    const TableReader t(table, "diffusion.edge." + std::to_string(index),
                        "[[diffusion.edge]] entry " + std::to_string(index),
                        {"edge", "depth", "box", "value"});
    constexpr Param kValue{"value", "the theta held on the region", "1.0"};
    sim::DiffusionEdge e;
    e.region = readRegion(t, sheet);
    e.value = t.requiredNumber(kValue, Range::any());
    return e;
}

sim::DiffusionParams readDiffusion(const TableReader& root, const sim::SheetParams& sheet) {
    const TableReader t = root.section(
        {"diffusion", "the diffusive quantity theta (acid, heat, moisture)", ""}, "[diffusion]",
        {"initial", "spot", "scatter", "edge"}, sectionFix("diffusion"));
    constexpr Param kInitial{"initial", "theta everywhere at t = 0", "0.0"};
    sim::DiffusionParams d;
    d.initial = t.number(kInitial, Range::any()).value_or(d.initial);
    for (const toml::table* table : tablesOf(t, "spot", "diffusion.spot")) {
        d.spots.push_back(readSpot(*table, d.spots.size(), sheet));
    }
    for (const toml::table* table : tablesOf(t, "scatter", "diffusion.scatter")) {
        d.scatters.push_back(readScatter(*table, d.scatters.size()));
    }
    for (const toml::table* table : tablesOf(t, "edge", "diffusion.edge")) {
        d.edges.push_back(readDiffusionEdge(*table, d.edges.size(), sheet));
    }
    return d;
}

// ---- [forces], [time] ------------------------------------------------------------------------

void readForces(const TableReader& root, sim::MembraneParams& p) {
    const TableReader t = root.section({"forces", "external forces", ""}, "[forces]",
                                       {"gravity", "damping", "pressure"}, sectionFix("forces"));
    constexpr Param kGravity{"gravity", "the gravitational acceleration [x, y, z] in m/s^2",
                             "[0.0, 0.0, -9.81]"};
    constexpr Param kDamping{"damping", "the velocity damping rate in 1/s", "0.1"};
    p.gravity = t.vec3(kGravity).value_or(p.gravity);
    p.damping = t.number(kDamping, Range::nonNegative()).value_or(p.damping);
    constexpr Param kPressure{"pressure", "a uniform pressure on the +z side in Pa", "100.0"};
    p.pressure = t.number(kPressure, Range::any()).value_or(p.pressure);
}

/// dt is a number or "auto"; returns where it was given, for the stability message.
std::string readTimeStep(const TableReader& t, sim::TimeParams& time) {
    constexpr Param kDt{"dt", "the time step in seconds", "1e-4"};
    const toml::node* node = t.find(kDt.key);
    if (!node) return t.location();
    if (const auto* text = node->as_string(); text && text->get() == "auto") {
        time.dt.reset();
    } else if (node->is_number()) {
        time.dt = t.number(kDt, Range::positive());
    } else {
        t.fail(kDt.key, "a number > 0 (the time step in seconds) or \"auto\"",
               scene::describeType(*node), "Use e.g. dt = 1e-4 or dt = \"auto\".");
    }
    return t.location(kDt.key);
}

std::string readTime(const TableReader& root, sim::TimeParams& time) {
    const TableReader t = root.section(
        {"time", "time stepping", ""}, "[time]",
        {"dt", "safety", "duration", "fps", "allow_unstable", "integrator"}, sectionFix("time"));
    constexpr Param kSafety{"safety", "the fraction of the stable time step used by dt = \"auto\"",
                            "0.8"};
    constexpr Param kDuration{"duration", "the simulated time in seconds", "5.0"};
    constexpr Param kFps{"fps", "the output frames per simulated second", "24"};
    constexpr Param kAllowUnstable{"allow_unstable", "whether dt may exceed the stable bound",
                                   "false"};

    const std::string dtLocation = readTimeStep(t, time);
    time.safety = t.number(kSafety, Range::openClosed(0.0, 1.0)).value_or(time.safety);
    time.duration = t.number(kDuration, Range::positive()).value_or(time.duration);
    time.fps = t.number(kFps, Range::positive()).value_or(time.fps);
    time.allowUnstable = t.boolean(kAllowUnstable).value_or(time.allowUnstable);
    constexpr Param kIntegrator{"integrator", "the explicit scheme", "\"velocity_verlet\""};
    static constexpr std::string_view kIntegrators[] = {"symplectic_euler", "velocity_verlet"};
    time.integrator =
        sim::Integrator(t.choice(kIntegrator, kIntegrators).value_or(std::size_t(time.integrator)));
    if (time.duration * time.fps > kMaxFrames) {
        t.fail(t.has(kDuration.key) ? kDuration.key : kFps.key,
               "at most 1e6 frames (duration * fps)",
               formatNumber(std::round(time.duration * time.fps)) + " frames",
               "Shorten duration or lower fps.");
    }
    return dtLocation;
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
    const TableReader t = root.section({"camera", "the camera", ""}, "[camera]",
                                       {"position", "look_at", "up", "fov"}, sectionFix("camera"));
    constexpr Param kPosition{"position", "the camera position [x, y, z] in metres",
                              "[0.0, -4.0, 3.0]"};
    constexpr Param kLookAt{"look_at", "the point the camera aims at [x, y, z] in metres",
                            "[0.0, 0.0, 0.0]"};
    constexpr Param kUp{"up", "the camera's up direction [x, y, z]", "[0.0, 0.0, 1.0]"};
    constexpr Param kFov{"fov", "the vertical field of view in degrees", "40"};

    render::Camera c = defaultCamera(sheet);
    c.position = t.vec3(kPosition).value_or(c.position);
    c.lookAt = t.vec3(kLookAt).value_or(c.lookAt);
    c.up = t.vec3(kUp, Range::any(), true).value_or(c.up);
    c.fovYDegrees = t.number(kFov, Range::open(1.0, 170.0)).value_or(c.fovYDegrees);

    const Eigen::Vector3d view = c.lookAt - c.position;
    if (view.norm() == 0.0) {
        t.fail(t.has(kPosition.key) ? kPosition.key : kLookAt.key,
               "a position different from look_at", "both at the same point",
               "Move the camera away from the point it looks at.");
    }
    if (view.normalized().cross(c.up.normalized()).norm() < 1e-6) {
        t.fail(t.has(kUp.key) ? kUp.key : kPosition.key,
               "an up direction not parallel to the view direction (look_at - position)",
               "them parallel", "Use e.g. up = [0.0, 0.0, 1.0] with a camera not straight above.");
    }
    return c;
}

void readLight(const TableReader& root, render::RenderSettings& r) {
    const TableReader t =
        root.section({"light", "the lighting", ""}, "[light]",
                     {"direction", "color", "intensity", "ambient"}, sectionFix("light"));
    constexpr Param kDirection{"direction", "from the surface towards the light [x, y, z]",
                               "[-0.4, -0.5, 1.0]"};
    constexpr Param kColor{"color", "the light's colour [r, g, b]", "[1.0, 1.0, 1.0]"};
    constexpr Param kIntensity{"intensity", "the light's strength", "0.85"};
    constexpr Param kAmbient{"ambient", "the ambient light level", "0.25"};
    r.sun.direction = t.vec3(kDirection, Range::any(), true).value_or(r.sun.direction);
    r.sun.color = t.vec3(kColor, Range::nonNegative()).value_or(r.sun.color);
    r.sun.intensity = t.number(kIntensity, Range::nonNegative()).value_or(r.sun.intensity);
    r.ambient = t.number(kAmbient, Range::closed(0.0, 1.0)).value_or(r.ambient);
}

std::optional<std::array<double, 2>> readColorRange(const TableReader& t) {
    constexpr Param kColorRange{"color_range", "the values mapped to the ends of the colour map",
                                "[0.0, 0.6]"};
    const std::optional<Eigen::Vector2d> range = t.vec2(kColorRange);
    if (!range) return std::nullopt;
    if (range->x() >= range->y()) {
        t.fail(kColorRange.key, "[lo, hi] with lo < hi (" + std::string(kColorRange.meaning) + ")",
               "[" + formatNumber(range->x()) + ", " + formatNumber(range->y()) + "]",
               TableReader::useInstead(kColorRange));
    }
    return std::array<double, 2>{range->x(), range->y()};
}

void readImage(const TableReader& t, Scene& scene) {
    constexpr Param kRenderer{"renderer", "the renderer", "\"osmesa\""};
    constexpr Param kWidth{"width", "the image width in pixels", "960"};
    constexpr Param kHeight{"height", "the image height in pixels", "540"};
    constexpr Param kSupersample{"supersample", "samples per pixel along each axis", "2"};
    constexpr Param kColorBy{"color_by", "what the surface colour shows", "\"strain\""};
    const Range pixels = Range::closed(16, 8192);
    render::RenderSettings& r = scene.render;
    scene.renderer = RendererKind(t.choice(kRenderer, kRenderers).value_or(0));
    r.width = int(t.integer(kWidth, pixels).value_or(r.width));
    r.height = int(t.integer(kHeight, pixels).value_or(r.height));
    r.supersample = int(t.integer(kSupersample, Range::closed(1, 4)).value_or(r.supersample));
    r.colorBy = render::ColorBy(t.choice(kColorBy, kColorModes).value_or(std::size_t(r.colorBy)));
    r.colorRange = readColorRange(t);
}

void readPathTracing(const TableReader& t, render::PathTracing& p) {
    constexpr Param kSpp{"spp", "path-traced samples per pixel", "16"};
    constexpr Param kDepth{"max_depth", "the longest light path in bounces", "4"};
    constexpr Param kMaterial{"material", "how the path tracer shades the sheet", "\"conductor\""};
    constexpr Param kRoughness{"roughness", "the surface roughness (GGX alpha = roughness^2)",
                               "0.35"};
    constexpr Param kTransmission{"transmission", "the fraction of light passing through", "0.3"};
    constexpr Param kSky{"sky", "a sky gradient instead of the constant background", "true"};
    constexpr Param kSunRadius{"sun_radius", "the sun's angular radius in degrees", "2.0"};
    constexpr Param kZenith{"sky_zenith", "the sky colour overhead [r, g, b]",
                            "[0.35, 0.50, 0.80]"};
    constexpr Param kHorizon{"sky_horizon", "the sky colour at the horizon [r, g, b]",
                             "[0.85, 0.88, 0.92]"};
    p.samplesPerPixel = int(t.integer(kSpp, Range::closed(1, 4096)).value_or(p.samplesPerPixel));
    p.maxDepth = int(t.integer(kDepth, Range::closed(1, 64)).value_or(p.maxDepth));
    p.material =
        render::MaterialKind(t.choice(kMaterial, kMaterials).value_or(std::size_t(p.material)));
    p.roughness = t.number(kRoughness, Range::closed(0.01, 1.0)).value_or(p.roughness);
    p.transmission = t.number(kTransmission, Range::closed(0.0, 1.0)).value_or(p.transmission);
    p.sky = t.boolean(kSky).value_or(p.sky);
    p.sunAngularRadiusDegrees =
        t.number(kSunRadius, Range::closed(0.0, 30.0)).value_or(p.sunAngularRadiusDegrees);
    p.skyZenith = t.vec3(kZenith, Range::closed(0.0, 10.0)).value_or(p.skyZenith);
    p.skyHorizon = t.vec3(kHorizon, Range::closed(0.0, 10.0)).value_or(p.skyHorizon);
}

void readSurface(const TableReader& t, render::RenderSettings& r) {
    constexpr Param kSurface{"surface", "how each frame becomes a surface", "\"lattice\""};
    constexpr Param kThickness{"thickness", "the lattice surface's extruded thickness in metres",
                               "0.002"};
    constexpr Param kVoxel{"vdb_voxel_size", "the level set's voxel size in metres (0: dx/2)",
                           "0.01"};
    constexpr Param kRadius{"vdb_particle_radius", "the particle radius in metres (0: 0.75 dx)",
                            "0.015"};
    constexpr Param kSmoothing{"vdb_smoothing", "level-set smoothing iterations", "1"};
    constexpr Param kAdaptivity{"vdb_adaptivity", "volumeToMesh adaptivity", "0.1"};
    r.surface = render::SurfaceKind(t.choice(kSurface, kSurfaces).value_or(std::size_t(r.surface)));
    r.thickness = t.number(kThickness, Range::nonNegative()).value_or(r.thickness);
    r.vdb.voxelSize = t.number(kVoxel, Range::nonNegative()).value_or(r.vdb.voxelSize);
    r.vdb.particleRadius = t.number(kRadius, Range::nonNegative()).value_or(r.vdb.particleRadius);
    r.vdb.smoothingIterations =
        int(t.integer(kSmoothing, Range::closed(0, 20)).value_or(r.vdb.smoothingIterations));
    r.vdb.adaptivity = t.number(kAdaptivity, Range::closed(0.0, 1.0)).value_or(r.vdb.adaptivity);
}

void readRender(const TableReader& root, const sim::SheetParams& sheet, Scene& scene) {
    const TableReader t = root.section({"render", "image settings", ""}, "[render]",
                                       {"renderer",      "width",          "height",
                                        "supersample",   "color_by",       "color_range",
                                        "albedo",        "background",     "ground_color",
                                        "ground",        "ground_height",  "spp",
                                        "max_depth",     "sky_zenith",     "sky_horizon",
                                        "material",      "roughness",      "transmission",
                                        "sky",           "sun_radius",     "surface",
                                        "thickness",     "vdb_voxel_size", "vdb_particle_radius",
                                        "vdb_smoothing", "vdb_adaptivity"},
                                       sectionFix("render"));
    constexpr Param kAlbedo{"albedo", "the surface colour [r, g, b]", "[0.78, 0.80, 0.85]"};
    constexpr Param kBackground{"background", "the sky colour [r, g, b]", "[0.80, 0.84, 0.90]"};
    constexpr Param kGroundColor{"ground_color", "the ground colour [r, g, b]",
                                 "[0.55, 0.55, 0.52]"};
    constexpr Param kGround{"ground", "whether to draw the ground plane", "true"};
    constexpr Param kGroundHeight{"ground_height", "the ground plane's z in metres", "-0.5"};
    const Range unit = Range::closed(0.0, 1.0);
    render::RenderSettings& r = scene.render;
    readImage(t, scene);
    readPathTracing(t, r.pathTracing);
    readSurface(t, r);
    r.albedo = t.vec3(kAlbedo, unit).value_or(r.albedo);
    r.background = t.vec3(kBackground, unit).value_or(r.background);
    r.groundColor = t.vec3(kGroundColor, unit).value_or(r.groundColor);
    r.ground = t.boolean(kGround).value_or(r.ground);
    // Half the sheet's size below it: out of the way of sagging, still in the picture.
    const double belowSheet = sheet.center.z() - 0.5 * extentOf(sheet).largest;
    r.groundHeight = t.number(kGroundHeight, Range::any()).value_or(belowSheet);
}

void readOutput(const TableReader& root, Scene& scene) {
    const TableReader t = root.section({"output", "output options", ""}, "[output]",
                                       {"stats", "export"}, sectionFix("output"));
    constexpr Param kStats{"stats", "whether to write per-frame statistics", "true"};
    constexpr Param kExport{"export", "per-frame files: any of \"ply\", \"obj\", \"glb\", \"vdb\"",
                            "[\"ply\", \"vdb\"]"};
    scene.writeStats = t.boolean(kStats).value_or(scene.writeStats);
    const toml::node* list = t.find(kExport.key);
    if (!list) return;
    const toml::array* formats = list->as_array();
    if (!formats)
        t.fail(kExport.key, "an array of format names", scene::describeType(*list),
               TableReader::useInstead(kExport));
    for (const toml::node& item : *formats) {
        const auto name = item.value<std::string>();
        const auto* hit =
            name ? std::find(std::begin(kExportFormats), std::end(kExportFormats), *name)
                 : std::end(kExportFormats);
        if (hit == std::end(kExportFormats))
            t.fail(kExport.key, "format names among \"ply\", \"obj\", \"glb\", \"vdb\"",
                   scene::describeType(item), TableReader::useInstead(kExport));
        scene.exports.push_back(ExportFormat(hit - std::begin(kExportFormats)));
    }
}

// `solver = "..."` at the top level: a name from the solver registry (sim/SolverRegistry.h),
// which also says what each solver takes. A scene asking for what its solver lacks is refused,
// not silently run without.
void readSolver(const TableReader& root, sim::MembraneParams& p) {
    constexpr Param kSolver{"solver", "the discretisation of the membrane", "\"fem_cst\""};
    std::vector<std::string_view> names;
    for (const sim::SolverEntry& entry : sim::solverRegistry()) names.push_back(entry.name);
    if (const auto k = root.choice(kSolver, names)) p.solver = std::string(names[*k]);
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

}  // namespace

int Scene::frameCount() const {
    return std::max(1, int(std::lround(sim.time.duration * sim.time.fps)));
}

std::filesystem::path assetsDirectory() {
    const char* env = std::getenv("REND_ASSETS");
    if (env && *env) return env;
    return REND_DEFAULT_ASSETS_DIR;
}

Scene loadScene(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
    const toml::table document = scene::buildSceneDocument(file, overrides, assetsDirectory());
    const TableReader root(document, "", "the top-level table",
                           {"solver", "sheet", "material", "boundary", "notch", "diffusion",
                            "forces", "time", "camera", "light", "render", "output"});
    Scene s;
    s.file = file;
    s.sim.sheet = readSheet(root);
    s.sim.material = readMaterial(root);
    s.sim.boundaries = readBoundaries(root, s.sim.sheet);
    s.sim.notches = readNotches(root);
    s.sim.diffusion = readDiffusion(root, s.sim.sheet);
    readForces(root, s.sim);
    readSolver(root, s.sim);
    s.dtLocation = readTime(root, s.sim.time);
    s.render.camera = readCamera(root, s.sim.sheet);
    readLight(root, s.render);
    readRender(root, s.sim.sheet, s);
    readOutput(root, s);
    s.resolvedJson = toJson(document);
    return s;
}

}  // namespace rend
