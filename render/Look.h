#pragma once
// The sheet's look: a material at theta = 0 (a preset a scene can override key by key, as a
// Blender or Houdini material preset is a starting point) and a layer that the diffusing
// quantity paints onto it. The layer modulates the material instead of replacing its colour:
// heated foil stays a metal with a temper tint, damp nori stays green, etched film stays
// translucent, wet paper stays paper. Both renderers shade from the same Shading.

#include <Eigen/Core>

#include "render/RenderSettings.h"

namespace rend::render {

/// One point's shading parameters, what both renderers build their material from.
struct Shading {
    MaterialKind kind = MaterialKind::Diffuse;
    /// Diffuse albedo, or for a conductor its reflectance at normal incidence (F0), which is the
    /// metal's specular tint. Linear RGB in [0, 1].
    Eigen::Vector3f color = Eigen::Vector3f::Constant(0.8f);
    float roughness = 0.35f;    ///< GGX alpha = roughness^2
    float transmission = 0.0f;  ///< fraction of light passing through the sheet

    /// 1 for a metal, 0 for a dielectric: a layer never turns one into the other.
    float metalness() const { return kind == MaterialKind::Conductor ? 1.0f : 0.0f; }
};

/// The material a look starts from: what `material`, `albedo`, `roughness` and `transmission`
/// default to in a scene that picks the look. Plain: RenderSettings' own defaults.
Shading lookPreset(Look look);

/// Writes lookPreset(settings.look) into the settings' material keys (the loader then reads a
/// scene's explicit keys over it).
void applyLookPreset(RenderSettings& settings);

/// The settings' material at theta = 0: material, albedo, roughness, transmission.
Shading baseShading(const RenderSettings& settings);

/// The shading of a point of the sheet: `base` under the look's layer. `theta` is the diffusing
/// quantity normalised to [0, 1] by color_range, `damage` the particle's damage in [0, 1]; both
/// are clamped. theta = damage = 0 gives `base` back unchanged, and the layer keeps base.kind.
Shading layeredShading(Look look, const Shading& base, float theta, float damage);

/// Foil's heat tint at theta in [0, 1], a factor on the metal's F0: white, then the temper
/// colours of a growing oxide film (straw, bronze, purple, blue), whose hue only ever moves one
/// way round the colour wheel as theta grows.
Eigen::Vector3f heatTint(float theta);

/// Whether a point's colour comes from the look (color_by none, or theta as a layer) rather
/// than from a map that replaces it (the paper's theta map, speed, strain, damage).
bool usesLookLayer(const RenderSettings& settings);

}  // namespace rend::render
