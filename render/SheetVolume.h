#pragma once
// The sheet as a volume for export (`--export vdb`): an OpenVDB narrow-band level set of the
// membrane at its own thickness, built from the mid-surface mesh (the lattice surface, so torn
// pieces stay apart) as the unsigned distance minus half the thickness
// (tools::meshToVolume with UNSIGNED_DISTANCE_FIELD). Beside it, the same shape as a `density`
// fog grid (what Blender and most renderers shade) and `theta`, the diffusing quantity of the
// closest triangle's corners. OpenVDB stays out of this header.
//
// A level set samples the distance at voxel centres, so a slab thinner than about two voxels
// has columns with no inside sample and falls apart into holes: the thickness written is the
// sheet's when the voxel is at most half of it, and two voxels otherwise (sheetVolumeThickness).

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "render/Mesh.h"

namespace rend::render {

/// The thickness the level set holds: the sheet's, or two voxels where that is more.
double sheetVolumeThickness(double sheetThickness, double voxelSize);

/// The level set's active voxels for a sheet of rest `area` [m^2] (a flat estimate: the
/// thickness plus the band outside both faces, over every column).
double sheetVolumeVoxels(double area, double voxelSize, double sheetThickness);

/// Bytes a frame's file takes per level-set voxel, the density grid with it (measured: 42.6 MB
/// for 8.09M voxels, blosc-compressed).
constexpr double kSheetVolumeBytesPerVoxel = 5.3;

struct SheetVolumeInfo {
    double voxelSize = 0.0;
    double thickness = 0.0;          ///< sheetVolumeThickness
    std::uint64_t activeVoxels = 0;  ///< of the level set
};

/// Writes `surface` (level set), `density` (fog, 1 inside) and, when `theta` is not empty,
/// `theta` (per particle, indexed by the mesh's Point::id) to `path` with writeFileAtomic.
/// Every grid carries the metadata `rend_thickness` and `rend_sheet_thickness` [m].
/// Throws std::invalid_argument on a non-positive size, std::runtime_error naming the path
/// when it cannot be written.
SheetVolumeInfo writeSheetVolume(const Mesh& midSurface, std::span<const double> theta,
                                 double voxelSize, double sheetThickness,
                                 const std::filesystem::path& path);

/// The value of the grid `name` of a .vdb at a world point (trilinear), for tests and tools.
/// Throws std::runtime_error when the file or the grid cannot be read.
float sampleVdb(const std::filesystem::path& path, const std::string& name,
                const Eigen::Vector3d& point);

}  // namespace rend::render
