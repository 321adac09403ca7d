#include "render/SheetVolume.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/GridOperators.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/Prune.h>

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "render/VdbIo.h"

namespace rend::render {
namespace {

// Voxels of the narrow band outside the surface, as OpenVDB's level sets have by default.
constexpr float kHalfWidthVoxels = 3.0f;

using IndexGrid = openvdb::Int32Grid;

/// The unsigned distance to the mid-surface over a band `reach` voxels wide, and each voxel's
/// closest triangle.
std::pair<openvdb::FloatGrid::Ptr, IndexGrid::Ptr> unsignedDistance(
    const Mesh& mid, const openvdb::math::Transform& xform, float reach) {
    std::vector<openvdb::Vec3s> points;
    points.reserve(mid.positions.size());
    for (const Eigen::Vector3f& p : mid.positions) {
        const openvdb::Vec3d index = xform.worldToIndex(openvdb::Vec3d(p.x(), p.y(), p.z()));
        points.emplace_back(float(index.x()), float(index.y()), float(index.z()));
    }
    std::vector<openvdb::Vec3I> triangles;
    triangles.reserve(mid.triangles.size());
    for (const auto& t : mid.triangles) triangles.emplace_back(t[0], t[1], t[2]);
    openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec3I> adapter(points,
                                                                                       triangles);
    IndexGrid::Ptr closest = IndexGrid::create(-1);
    openvdb::FloatGrid::Ptr distance = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
        adapter, xform, reach, reach, openvdb::tools::UNSIGNED_DISTANCE_FIELD, closest.get());
    return {distance, closest};
}

/// distance - thickness / 2 where it is under the band's half width; the background outside.
void offsetToLevelSet(openvdb::FloatGrid& grid, double thickness, double voxel) {
    const float half = float(0.5 * thickness), background = float(kHalfWidthVoxels * voxel);
    for (auto v = grid.beginValueOn(); v; ++v) {
        const float value = *v - half;
        v.setValue(std::min(value, background));
        if (value >= background) v.setValueOff();
    }
    grid.tree().root().setBackground(background, /*updateChildNodes=*/true);
    openvdb::tools::pruneInactive(grid.tree());
    grid.setGridClass(openvdb::GRID_LEVEL_SET);
}

/// Each active voxel of `shape` gets the mean theta of its closest triangle's particles.
openvdb::FloatGrid::Ptr thetaGrid(const openvdb::FloatGrid& shape, const IndexGrid& closest,
                                  const Mesh& mid, std::span<const double> theta) {
    openvdb::FloatGrid::Ptr values = openvdb::FloatGrid::create(0.0f);
    values->setTransform(shape.transform().copy());
    values->insertMeta(shape);  // the thickness
    values->setGridClass(openvdb::GRID_FOG_VOLUME);
    auto out = values->getAccessor();
    auto triangle = closest.getConstAccessor();
    const auto particle = [&](std::uint32_t vertex) {
        const std::int32_t id = mid.points.empty() ? std::int32_t(vertex) : mid.points[vertex].id;
        return id >= 0 && std::size_t(id) < theta.size() ? theta[std::size_t(id)] : 0.0;
    };
    for (auto v = shape.cbeginValueOn(); v; ++v) {
        const std::int32_t t = triangle.getValue(v.getCoord());
        if (t < 0 || std::size_t(t) >= mid.triangles.size()) continue;
        double sum = 0.0;
        for (const std::uint32_t corner : mid.triangles[std::size_t(t)]) sum += particle(corner);
        out.setValue(v.getCoord(), float(sum / 3.0));
    }
    return values;
}

}  // namespace

double sheetVolumeThickness(double sheetThickness, double voxelSize) {
    return std::max(sheetThickness, 2.0 * voxelSize);
}

double sheetVolumeVoxels(double area, double voxelSize, double sheetThickness) {
    const double thickness = sheetVolumeThickness(sheetThickness, voxelSize);
    return area / (voxelSize * voxelSize) * (thickness / voxelSize + 2.0 * kHalfWidthVoxels);
}

SheetVolumeInfo writeSheetVolume(const Mesh& midSurface, std::span<const double> theta,
                                 double voxelSize, double sheetThickness,
                                 const std::filesystem::path& path) {
    if (!(voxelSize > 0.0) || !(sheetThickness > 0.0))
        throw std::invalid_argument("sheet volume: the voxel size and thickness must be > 0");
    vdb::initialize();
    const double thickness = sheetVolumeThickness(sheetThickness, voxelSize);
    const auto xform = openvdb::math::Transform::createLinearTransform(voxelSize);
    // The band reaches half the thickness and then the level set's own half width beyond it.
    const float reach = float(0.5 * thickness / voxelSize) + kHalfWidthVoxels + 1.0f;
    auto [surface, closest] = unsignedDistance(midSurface, *xform, reach);
    offsetToLevelSet(*surface, thickness, voxelSize);
    surface->setName("surface");
    surface->insertMeta("rend_thickness", openvdb::FloatMetadata(float(thickness)));
    surface->insertMeta("rend_sheet_thickness", openvdb::FloatMetadata(float(sheetThickness)));
    // Blender and most renderers shade a fog volume named "density", not a level set.
    openvdb::FloatGrid::Ptr density = surface->deepCopy();
    openvdb::tools::sdfToFogVolume(*density);
    density->setName("density");
    openvdb::GridCPtrVec grids{surface, density};
    if (!theta.empty()) {
        openvdb::FloatGrid::Ptr values = thetaGrid(*surface, *closest, midSurface, theta);
        values->setName("theta");
        grids.push_back(values);
    }
    vdb::writeGridsAtomic(path, grids);
    return {voxelSize, thickness, surface->activeVoxelCount()};
}

float sampleVdb(const std::filesystem::path& path, const std::string& name,
                const Eigen::Vector3d& point) {
    vdb::initialize();
    try {
        openvdb::io::File file(path.string());
        file.open();
        const auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid(name));
        if (!grid) throw std::runtime_error("grid " + name + " is not a float grid");
        const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sampler(
            *grid);
        return sampler.wsSample(openvdb::Vec3d(point.x(), point.y(), point.z()));
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot read " + path.string() + ": " + e.what());
    }
}

}  // namespace rend::render
