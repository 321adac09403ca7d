#pragma once
// Linear radiance to 8-bit display values, shared by both renderers: exposure, a tone curve and
// the 2.2 display gamma, so the two renderers' frames stay comparable.

#include <cstdint>
#include <span>

#include "render/RenderSettings.h"

namespace rend::render {

/// The filmic curve on its own: 0 at 0, increasing, below 1 for every finite x and tending to 1,
/// with a toe that deepens the shadows a little and a shoulder that rolls highlights off instead
/// of clipping them. Narkowicz's least-squares fit of the ACES reference rendering transform
/// ("ACES Filmic Tone Mapping Curve", 2016): s (a s + b) / (s (c s + d) + e) of s = 0.7415 x,
/// which keeps 18% grey at 0.18, divided by its limit a / c so that white is reached only at
/// infinite radiance.
double filmicCurve(double x);

/// Display-linear value in [0, 1] of a linear radiance: scaled by 2^exposure, then the filmic
/// curve or a clamp. NaN and negative radiance give 0.
double toneMap(double linear, const ToneMapping& tone);

/// toneMap, then the 2.2 display gamma, rounded to a byte.
std::uint8_t displayByte(double linear, const ToneMapping& tone);

/// displayByte of every value of `linear` into `bytes` (as many): the same bytes, a frame's
/// pixels at a time.
void displayBytes(std::span<const double> linear, std::span<std::uint8_t> bytes,
                  const ToneMapping& tone);
void displayBytes(std::span<const float> linear, std::span<std::uint8_t> bytes,
                  const ToneMapping& tone);

}  // namespace rend::render
