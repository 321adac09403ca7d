#pragma once
#include <Eigen/Core>
#include <span>
#include <vector>

#include "render/RenderSettings.h"
#include "sim/FrameView.h"

namespace rend::render {

/// The per-particle scalar a ColorBy selects: |v| for Speed, the mean bond strain
/// (|x_j - x_i| / |x0_j - x0_i| - 1 over intact bonds) for Strain; empty for None.
std::vector<double> particleField(const sim::FrameView& frame, ColorBy by);

/// Perceptual map (dark blue -> teal -> yellow, viridis-like) of t in [0,1], linear RGB.
Eigen::Vector3f colormap(double t);

/// Per-particle colours: albedo for None, else colormap over the settings' range.
std::vector<Eigen::Vector3f> particleColors(const sim::FrameView& frame,
                                            const RenderSettings& settings);

}  // namespace rend::render
