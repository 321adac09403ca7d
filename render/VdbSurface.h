#pragma once
// The `vdb` surface: every particle a sphere rasterised into an OpenVDB narrow-band level set
// (tools::ParticlesToLevelSet), lightly smoothed, and meshed at the zero crossing
// (tools::volumeToMesh). The result is a closed, watertight skin around the particles (a thin
// "pillow" about 1.5 dx thick for a sheet) that opens wherever the particles separate.
// OpenVDB stays out of this header: rend_render links it privately. (`--export vdb` writes the
// sheet at its own thickness instead: render/SheetVolume.h.)

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "render/Mesh.h"
#include "render/RenderSettings.h"
#include "sim/FrameView.h"

namespace rend::render {

class VdbSurface {
public:
    /// Resolves the settings' defaults from the rest spacing dx (render/SplatSurface.h
    /// restSpacing): voxel dx / 2 when voxelSize is 0, radius 0.75 dx when particleRadius is 0.
    /// Throws std::invalid_argument when a size is not positive, when dx is needed but the rest
    /// lattice has none, or when the radius is below 1.5 voxels: OpenVDB silently skips such
    /// particles (ParticlesToLevelSet::setRmin), which would open holes instead of failing.
    VdbSurface(const sim::FrameView& rest, const VdbSettings& settings);
    ~VdbSurface();
    VdbSurface(VdbSurface&&) noexcept;
    VdbSurface& operator=(VdbSurface&&) noexcept;

    /// Rasterises the frame's particles, smooths (settings.vdb is ignored here: the surface
    /// keeps the settings it was made with), meshes the zero level set with quads split into
    /// triangles, and gives every vertex an area-weighted outward normal and the colour of its
    /// nearest particle (particleColors).
    Mesh build(const sim::FrameView& frame, const RenderSettings& settings);

    /// Particles OpenVDB skipped in the last build (too small or too large for the grid).
    /// The radius check in the constructor keeps this at 0; it is recorded to prove it.
    int droppedParticles() const { return dropped_; }

    double voxelSize() const { return voxelSize_; }
    double particleRadius() const { return radius_; }
    /// Active voxels of the last built grid; 0 before the first build.
    std::uint64_t activeVoxelCount() const;

private:
    struct Grid;  // wraps openvdb::FloatGrid::Ptr

    double voxelSize_ = 0.0;
    double radius_ = 0.0;
    int smoothingIterations_ = 0;
    double adaptivity_ = 0.0;
    int dropped_ = 0;
    std::unique_ptr<Grid> grid_;
};

/// What a .vdb file holds, read back with openvdb::io::File (for tests and tools that must
/// not include OpenVDB themselves).
struct VdbFileInfo {
    std::size_t gridCount = 0;
    std::string firstGridName;
    std::uint64_t firstGridActiveVoxels = 0;
    double firstGridVoxelSize = 0.0;
    std::vector<std::string> gridNames;       ///< in file order
    std::vector<std::uint64_t> activeVoxels;  ///< per grid
    std::vector<std::array<float, 2>> range;  ///< per float grid, its active values' min and max
};

/// Throws std::runtime_error when the file cannot be read.
VdbFileInfo inspectVdb(const std::filesystem::path& path);

}  // namespace rend::render
