#pragma once
// One name table per enum that a scene file or the command line spells out. Each table follows
// its enum's order, so an index converts straight to the enum; the loader, `rend run`'s options
// and the README's scene table all read these.

#include <optional>
#include <span>
#include <string_view>

namespace rend::names {

inline constexpr std::string_view kShapes[] = {"rectangle", "disc", "sphere"};  // sim::Outline
inline constexpr std::string_view kColliderShapes[] = {"sphere", "box", "capsule",
                                                       "mesh"};  // sim::ColliderShape
inline constexpr std::string_view kLattices[] = {"hexagonal", "square"};
inline constexpr std::string_view kQualities[] = {"preview", "final"};  // rend::Quality
inline constexpr std::string_view kMicromoduli[] = {"calibrated", "paper"};
inline constexpr std::string_view kLaws[] = {"linear", "power_law", "elastoplastic"};
inline constexpr std::string_view kCriticalStretches[] = {"calibrated", "paper", "preview",
                                                          "midway"};
inline constexpr std::string_view kMappedProperties[] = {
    "E",         "fracture_energy", "density",       "yield_strain",
    "softening", "power_ratio",     "power_exponent"};  // sim::MappedProperty
inline constexpr std::string_view kMapShapes[] = {"box", "disc", "polygon", "noise",
                                                  "image"};  // sim::MapShape
inline constexpr std::string_view kBoundaryTypes[] = {"velocity", "pinned"};
inline constexpr std::string_view kEdges[] = {"left", "right", "bottom", "top"};
inline constexpr std::string_view kIntegrators[] = {"symplectic_euler", "velocity_verlet"};
inline constexpr std::string_view kRenderers[] = {"osmesa", "none", "embree"};
inline constexpr std::string_view kSurfaces[] = {"lattice", "splat", "vdb", "particle_level_set"};
inline constexpr std::string_view kMaterials[] = {"diffuse", "conductor", "film", "translucent"};
inline constexpr std::string_view kExportFormats[] = {"ply", "obj", "glb", "vdb"};
inline constexpr std::string_view kColorModes[] = {"none", "speed", "strain", "theta", "damage"};
inline constexpr std::string_view kLooks[] = {"plain", "foil", "film", "seaweed", "paper"};
inline constexpr std::string_view kThetaStyles[] = {"layer", "paper_map"};
inline constexpr std::string_view kToneMaps[] = {"filmic", "clamp"};
/// The words that stand for "no number": dt = "adaptive" or "auto", fracture_energy = "none".
/// dt's first word is its default (sim::StepControl in this order, reversed).
inline constexpr std::string_view kStepWords[] = {"adaptive", "auto"};
inline constexpr std::string_view kNone[] = {"none"};

/// Index of `name` in `table`, if it is there.
inline std::optional<std::size_t> indexOf(std::span<const std::string_view> table,
                                          std::string_view name) {
    for (std::size_t k = 0; k < table.size(); ++k)
        if (table[k] == name) return k;
    return std::nullopt;
}

}  // namespace rend::names
