#pragma once
// Everything a frame writes besides stats: the surface (lattice, splat or vdb), the PNG through
// OSMesa or Embree, and the per-frame mesh and level-set exports. Each piece is created on first
// use, so a run that writes none of them builds no surface at all (DESIGN.md: a skipped stage
// costs nothing).

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "app/Scene.h"
#include "render/Geometry.h"
#include "render/Image.h"
#include "sim/FrameView.h"

namespace rend {

struct StageTimes;

class FrameWriter {
public:
    FrameWriter(const Scene& scene, const std::filesystem::path& outDir);
    ~FrameWriter();

    /// Whether frames produce any file (a PNG or an export).
    bool active() const;

    /// Writes the frame's files; returns their paths relative to the output folder.
    std::vector<std::string> write(const sim::FrameView& view, StageTimes& seconds);

private:
    render::Geometry buildSurface(const sim::FrameView& view);
    render::Image renderImage(const render::Geometry& geometry);
    void exportFrame(const sim::FrameView& view, const render::Geometry& geometry,
                     std::vector<std::string>& written);

    struct Parts;
    const Scene& scene_;
    std::filesystem::path outDir_;
    std::unique_ptr<Parts> parts_;
};

}  // namespace rend
