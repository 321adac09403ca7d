#pragma once
#include <cstdint>
#include <filesystem>
#include <vector>

namespace rend::render {

/// 8-bit RGB image, top row first.
struct Image {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgb;  ///< width * height * 3
};

/// Encodes a PNG with stb_image_write and writes it with writeFileAtomic (render/AtomicFile.h):
/// a reader never sees a half-written frame, and a failed write throws naming the path and the
/// reason, leaving nothing under `path`.
void writePngAtomic(const Image& image, const std::filesystem::path& path);

/// Reads an 8-bit PNG (any channel count, converted to RGB). Throws on failure.
Image readPng(const std::filesystem::path& path);

/// Per-pixel comparison for image regression tests (Blender's idiff style).
struct ImageDiff {
    double failingFraction = 1.0;  ///< fraction of pixels whose max channel diff > tolerance
    int maxDifference = 255;
    Image diff;  ///< visualisation: failing pixels red over a darkened reference
};
ImageDiff compareImages(const Image& reference, const Image& actual, int tolerance);

}  // namespace rend::render
