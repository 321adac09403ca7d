#pragma once
// OpenEXR frames for compositing (Nuke, Blender's compositor): the path tracer's linear radiance
// before any tone curve, and the first hit's depth, normal and theta as extra channels of one
// single-part file.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace rend::render {

/// Per-pixel linear layers of one frame, top row first. Empty vectors are not written.
struct FrameLayers {
    int width = 0;
    int height = 0;
    std::vector<float> rgb;     ///< linear radiance, 3 per pixel, before the tone curve
    std::vector<float> depth;   ///< distance from the camera to the first hit [m]; kNoHit if none
    std::vector<float> normal;  ///< world-space unit shading normal facing the camera, 3 per pixel
    std::vector<float> theta;   ///< the diffusing quantity at the first hit

    /// Depth where a pixel's centre ray hits nothing: Blender's background Z, finite so a
    /// compositor's depth operations do not turn it into NaN.
    static constexpr float kNoHit = 1e10f;
};

/// Writes `layers` as an EXR with ZIP compression: R, G, B (half), Z (float), N.X, N.Y, N.Z
/// (half) and theta (half), each only when present. Written like every other output
/// (writeFileAtomic: NAME.tmp, then a rename); throws std::invalid_argument for layers whose
/// sizes disagree and std::system_error naming the path when the write fails.
void writeExrAtomic(const FrameLayers& layers, const std::filesystem::path& path);

/// Every channel of an EXR's first part as floats, top row first, with its size. Throws
/// std::runtime_error naming the path on failure. For tests and the render benchmark.
struct ExrChannels {
    int width = 0;
    int height = 0;
    std::map<std::string, std::vector<float>> channels;
};
ExrChannels readExr(const std::filesystem::path& path);

}  // namespace rend::render
