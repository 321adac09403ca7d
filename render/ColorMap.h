#pragma once
#include <Eigen/Core>
#include <span>
#include <vector>

#include "render/RenderSettings.h"
#include "sim/FrameView.h"

namespace rend::render {

/// The per-particle scalar a ColorBy selects: |v| for Speed, the mean bond strain
/// (|x_j - x_i| / |x0_j - x0_i| - 1 over intact bonds) for Strain, FrameView::theta for Theta
/// and FrameView::damage for Damage (zeros where the frame has none); empty for None.
std::vector<double> particleField(const sim::FrameView& frame, ColorBy by);

/// Perceptual map (dark blue -> teal -> yellow, viridis-like) of t in [0,1], linear RGB.
Eigen::Vector3f colormap(double t);

/// The membrane paper's theta map of t in [0,1], linear RGB: light (pale pink-red) at 0 to dark
/// red at 1, so that a sheet with no theta looks like a light, slightly reddish material.
Eigen::Vector3f thetaColormap(double t);

/// Per-particle inputs of the look's layer (render/Look.h): (theta normalised to [0, 1] by the
/// settings' range, damage), theta 0 for ColorBy::None; empty where a map replaces the look
/// (usesLookLayer false). Surfaces carry them to the renderers as Mesh::layers.
std::vector<Eigen::Vector2f> particleLayers(const sim::FrameView& frame,
                                            const RenderSettings& settings);

/// Per-particle colours: the look's colour (layeredShading of particleLayers) for None and for
/// Theta as a layer, thetaColormap for Theta as the paper's map, colormap for the others, over
/// the settings' range (default 0..max of the field). Damage uses viridis rather than a
/// white-to-black ramp because the renderer's shading already varies brightness: only a map
/// that also changes hue stays readable on a lit, folded sheet.
std::vector<Eigen::Vector3f> particleColors(const sim::FrameView& frame,
                                            const RenderSettings& settings);

}  // namespace rend::render
