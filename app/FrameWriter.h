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
#include "render/ExrWriter.h"
#include "render/Geometry.h"
#include "render/Image.h"
#include "render/LatticeSurface.h"
#include "render/SheetVolume.h"
#include "sim/FrameView.h"

namespace rend {

struct StageTimes;

class FrameWriter {
public:
    /// Throws SceneError when the scene asks for EXR frames from the osmesa renderer.
    FrameWriter(const Scene& scene, const std::filesystem::path& outDir);
    ~FrameWriter();

    /// Whether frames produce any file (a PNG or an export).
    bool active() const;

    /// The files write() makes for `frame`, relative to the output folder (an OBJ's .mtl too).
    std::vector<std::string> plannedFiles(int frame) const;

    /// Writes the frame's files, appending each one's path relative to the output folder to
    /// `written` as soon as it is complete (so a failed write leaves the list right).
    void write(const sim::FrameView& view, StageTimes& seconds, std::vector<std::string>& written);

    /// The last exported volume's voxel size and thickness (render/SheetVolume.h); zeros before
    /// the first `--export vdb` frame.
    render::SheetVolumeInfo lastVolume() const { return lastVolume_; }

private:
    /// The frame's surface, built into the last frame's (Parts::geometry) where it is a mesh.
    const render::Geometry& buildSurface(const sim::FrameView& view);
    /// The lattice surface, or with surface = "particle_level_set" its level-set outline; the
    /// exports' mid-surface is the same one.
    render::LatticeSurface& meshSurface(const sim::FrameView& view);
    /// The sheet's mid-surface (the lattice surface, not extruded) for the volume export.
    const render::Mesh& midSurface(const sim::FrameView& view, const render::Geometry& geometry,
                                   render::Mesh& scratch);
    bool writesExr() const;  ///< [output] exr with the path tracer
    /// The frame's PNG image; with the path tracer also its EXR layers when `layers` is given.
    render::Image renderImage(const sim::FrameView& view, const render::Geometry& geometry,
                              render::FrameLayers* layers);
    void exportFrame(const sim::FrameView& view, const render::Geometry& geometry,
                     std::vector<std::string>& written);

    struct Parts;
    const Scene& scene_;
    std::filesystem::path outDir_;
    std::unique_ptr<Parts> parts_;
    render::SheetVolumeInfo lastVolume_;
};

}  // namespace rend
