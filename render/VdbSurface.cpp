#include "render/VdbSurface.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetFilter.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/ParticlesToLevelSet.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "render/AtomicFile.h"
#include "render/ColorMap.h"
#include "render/SplatSurface.h"
#include "render/VdbIo.h"

namespace rend::render {

namespace {

constexpr double kDefaultVoxelFactor = 0.5;    // voxel = dx / 2
constexpr double kDefaultRadiusFactor = 0.75;  // radius = 0.75 dx: a ~1.5 dx thick pillow
constexpr double kMinRadiusVoxels = 1.5;       // OpenVDB's default Rmin
// The narrow band must hold the whole pillow's interior plus room for the filter's stencils.
constexpr double kHalfWidthVoxels = 3.0;
constexpr const char* kGridName = "surface";

// The ParticleList contract of tools/ParticlesToLevelSet.h over a frame's positions, with one
// radius for every particle.
class ParticleList {
public:
    using PosType = openvdb::Vec3R;

    ParticleList(std::span<const Eigen::Vector3d> positions, double radius)
        : positions_(positions), radius_(radius) {}

    std::size_t size() const { return positions_.size(); }
    void getPos(std::size_t n, openvdb::Vec3R& xyz) const {
        const Eigen::Vector3d& p = positions_[n];
        xyz = openvdb::Vec3R(p.x(), p.y(), p.z());
    }
    void getPosRad(std::size_t n, openvdb::Vec3R& xyz, openvdb::Real& radius) const {
        getPos(n, xyz);
        radius = radius_;
    }

private:
    std::span<const Eigen::Vector3d> positions_;
    double radius_;
};

double resolveSize(double requested, double factor, double dx, const char* what) {
    if (requested < 0.0 || !std::isfinite(requested))
        throw std::invalid_argument(std::string("vdb surface: ") + what +
                                    " must be >= 0 (0: from the rest spacing)");
    if (requested > 0.0) return requested;
    if (dx <= 0.0)
        throw std::invalid_argument(std::string("vdb surface: ") + what +
                                    " = 0 needs the rest spacing, but the rest lattice has no "
                                    "bond and no triangle; give it explicitly");
    return factor * dx;
}

// Quads split along their shorter diagonal, which keeps the triangles closer to equilateral.
void appendQuad(const std::vector<openvdb::Vec3s>& points, const openvdb::Vec4I& q,
                std::vector<std::array<std::uint32_t, 3>>& triangles) {
    const float d02 = (points[q[0]] - points[q[2]]).lengthSqr();
    const float d13 = (points[q[1]] - points[q[3]]).lengthSqr();
    if (d02 <= d13) {
        triangles.push_back({q[0], q[1], q[2]});
        triangles.push_back({q[0], q[2], q[3]});
    } else {
        triangles.push_back({q[0], q[1], q[3]});
        triangles.push_back({q[1], q[2], q[3]});
    }
}

// Six times the signed volume the triangles enclose: positive when they face outward.
double signedVolume6(const Mesh& mesh) {
    double volume = 0.0;
    for (const auto& t : mesh.triangles) {
        const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>();
        const Eigen::Vector3d b = mesh.positions[t[1]].cast<double>();
        const Eigen::Vector3d c = mesh.positions[t[2]].cast<double>();
        volume += a.dot(b.cross(c));
    }
    return volume;
}

// volumeToMesh's winding is a convention of the library, not a documented promise, so the
// outward side is checked rather than assumed: every component of a level set's zero crossing
// has the same orientation, so the sign of the total enclosed volume decides for all.
void orientOutward(Mesh& mesh) {
    if (signedVolume6(mesh) >= 0.0) return;
    for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
}

std::vector<Eigen::Vector3f> areaWeightedNormals(const Mesh& mesh) {
    std::vector<Eigen::Vector3f> normals(mesh.positions.size(), Eigen::Vector3f::Zero());
    for (const auto& t : mesh.triangles) {
        const Eigen::Vector3f& a = mesh.positions[t[0]];
        const Eigen::Vector3f n = (mesh.positions[t[1]] - a).cross(mesh.positions[t[2]] - a);
        for (std::uint32_t v : t) normals[v] += n;
    }
    for (auto& n : normals) {
        const float len = n.norm();
        n = len > 0.0f ? Eigen::Vector3f(n / len) : Eigen::Vector3f::UnitZ();
    }
    return normals;
}

// Uniform-grid hash of particle positions for nearest-particle queries: cells sorted by key,
// each holding a contiguous run of particle indices.
class ParticleHash {
public:
    ParticleHash(std::span<const Eigen::Vector3d> positions, double cell)
        : positions_(positions), inverseCell_(1.0 / cell) {
        std::vector<std::pair<std::uint64_t, int>> keyed;
        keyed.reserve(positions.size());
        for (int i = 0; i < int(positions.size()); ++i)
            keyed.emplace_back(key(cellOf(positions[i])), i);
        std::sort(keyed.begin(), keyed.end());
        order_.reserve(keyed.size());
        for (std::size_t k = 0; k < keyed.size(); ++k) {
            if (k == 0 || keyed[k].first != keyed[k - 1].first) {
                keys_.push_back(keyed[k].first);
                starts_.push_back(int(k));
            }
            order_.push_back(keyed[k].second);
        }
        starts_.push_back(int(order_.size()));
    }

    /// Nearest particle to p, or -1 when there are no particles.
    int nearest(const Eigen::Vector3d& p) const {
        if (positions_.empty()) return -1;
        const Eigen::Vector3i centre = cellOf(p);
        int best = -1;
        double bestDistance = std::numeric_limits<double>::infinity();
        // A cube of half-size `ring` cells holds every particle within ring cells of p, so
        // once the best distance is below that, no farther cell can hold a closer one.
        for (int ring = 1; ring <= kMaxRing; ++ring) {
            searchCube(p, centre, ring, best, bestDistance);
            if (best >= 0 && std::sqrt(bestDistance) * inverseCell_ <= ring) return best;
        }
        return best >= 0 ? best : bruteForce(p);
    }

private:
    static constexpr int kMaxRing = 4;
    static constexpr int kBias = 1 << 20;  // 21 bits per axis: +-1M cells

    Eigen::Vector3i cellOf(const Eigen::Vector3d& p) const {
        return (p * inverseCell_).array().floor().cast<int>();
    }
    static std::uint64_t key(const Eigen::Vector3i& c) {
        auto field = [](int v) { return std::uint64_t(std::uint32_t(v + kBias) & 0x1FFFFF); };
        return field(c.x()) | (field(c.y()) << 21) | (field(c.z()) << 42);
    }

    void searchCube(const Eigen::Vector3d& p, const Eigen::Vector3i& centre, int ring, int& best,
                    double& bestDistance) const {
        for (int z = -ring; z <= ring; ++z)
            for (int y = -ring; y <= ring; ++y)
                for (int x = -ring; x <= ring; ++x)
                    searchCell(p, centre + Eigen::Vector3i(x, y, z), best, bestDistance);
    }

    void searchCell(const Eigen::Vector3d& p, const Eigen::Vector3i& cell, int& best,
                    double& bestDistance) const {
        const auto it = std::lower_bound(keys_.begin(), keys_.end(), key(cell));
        if (it == keys_.end() || *it != key(cell)) return;
        const std::size_t k = std::size_t(it - keys_.begin());
        for (int s = starts_[k]; s < starts_[k + 1]; ++s) {
            const double d = (positions_[order_[s]] - p).squaredNorm();
            if (d < bestDistance || (d == bestDistance && order_[s] < best)) {
                bestDistance = d;
                best = order_[s];
            }
        }
    }

    int bruteForce(const Eigen::Vector3d& p) const {
        int best = 0;
        for (int i = 1; i < int(positions_.size()); ++i)
            if ((positions_[i] - p).squaredNorm() < (positions_[best] - p).squaredNorm()) best = i;
        return best;
    }

    std::span<const Eigen::Vector3d> positions_;
    double inverseCell_;
    std::vector<std::uint64_t> keys_;
    std::vector<int> starts_;
    std::vector<int> order_;
};

/// Each vertex takes its nearest particle's colour and look layer.
void nearestParticleColors(const sim::FrameView& frame, const RenderSettings& settings, Mesh& mesh,
                           double cell) {
    const std::vector<Eigen::Vector3f> particle = particleColors(frame, settings);
    const std::vector<Eigen::Vector2f> layers = particleLayers(frame, settings);
    const ParticleHash hash(frame.positions, cell);
    mesh.colors.assign(mesh.positions.size(), settings.albedo.cast<float>());
    if (!layers.empty()) mesh.layers.assign(mesh.positions.size(), Eigen::Vector2f::Zero());
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
        const int nearest = hash.nearest(mesh.positions[v].cast<double>());
        if (nearest < 0) continue;
        if (std::size_t(nearest) < particle.size()) mesh.colors[v] = particle[nearest];
        if (std::size_t(nearest) < layers.size()) mesh.layers[v] = layers[nearest];
    }
}

}  // namespace

struct VdbSurface::Grid {
    openvdb::FloatGrid::Ptr levelSet;
};

VdbSurface::VdbSurface(const sim::FrameView& rest, const VdbSettings& settings)
    : smoothingIterations_(settings.smoothingIterations), adaptivity_(settings.adaptivity) {
    const bool needsSpacing = settings.voxelSize == 0.0 || settings.particleRadius == 0.0;
    const double dx = needsSpacing ? restSpacing(rest) : 0.0;
    voxelSize_ = resolveSize(settings.voxelSize, kDefaultVoxelFactor, dx, "voxelSize");
    radius_ = resolveSize(settings.particleRadius, kDefaultRadiusFactor, dx, "particleRadius");
    // The relative slack lets "exactly 1.5 voxels" through despite rounding in 1.5 * voxel.
    if (radius_ < kMinRadiusVoxels * voxelSize_ * (1.0 - 1e-9))
        throw std::invalid_argument(
            "vdb surface: particle radius " + std::to_string(radius_) + " is below 1.5 voxels (" +
            std::to_string(kMinRadiusVoxels * voxelSize_) +
            "); OpenVDB would skip every particle. Use a smaller voxelSize or a larger radius.");
    if (smoothingIterations_ < 0)
        throw std::invalid_argument("vdb surface: smoothingIterations must be >= 0");
    if (!(adaptivity_ >= 0.0 && adaptivity_ <= 1.0))
        throw std::invalid_argument("vdb surface: adaptivity must be in [0, 1]");
    vdb::initialize();
}

VdbSurface::~VdbSurface() = default;
VdbSurface::VdbSurface(VdbSurface&&) noexcept = default;
VdbSurface& VdbSurface::operator=(VdbSurface&&) noexcept = default;

namespace {

/// The particles' spheres as a narrow-band level set.
openvdb::FloatGrid::Ptr rasterize(std::span<const Eigen::Vector3d> positions, double voxel,
                                  double radius, int& dropped) {
    openvdb::FloatGrid::Ptr grid =
        openvdb::createLevelSet<openvdb::FloatGrid>(voxel, kHalfWidthVoxels);
    grid->setName(kGridName);
    openvdb::tools::ParticlesToLevelSet<openvdb::FloatGrid> raster(*grid);
    // The constructor already refused radii below 1.5 voxels; the slack only keeps a radius of
    // exactly 1.5 voxels from being dropped by rounding in radius / voxel.
    raster.setRmin(kMinRadiusVoxels * (1.0 - 1e-9));
    raster.rasterizeSpheres(ParticleList(positions, radius));
    raster.finalize(/*prune=*/true);
    dropped = int(raster.getMinCount() + raster.getMaxCount());
    return grid;
}

// Mean-curvature flow moves a flat sheet's faces not at all and fills the dimples between
// the spheres, so unlike a Gaussian blur of the distance values it cannot eat through a pillow
// only ~3 voxels thick (tested).
//
// After each step the filter re-tracks the narrow band. Its default (3 renormalisation sweeps
// with fifth-order WENO gradients) took 80% of a frame (400 ms of 570 ms on the 11.6K sheet,
// 2 cores); one first-order sweep is ~7x cheaper, and a light smoothing that is meshed at the
// voxel size right after needs no more (the topology and thickness tests pass either way).
void smooth(openvdb::FloatGrid& grid, int iterations) {
    if (iterations <= 0 || grid.activeVoxelCount() == 0) return;
    openvdb::tools::LevelSetFilter<openvdb::FloatGrid> filter(grid);
    filter.setSpatialScheme(openvdb::math::FIRST_BIAS);
    filter.setNormCount(1);
    for (int k = 0; k < iterations; ++k) filter.meanCurvature();
}

Mesh zeroCrossing(const openvdb::FloatGrid& grid, double adaptivity) {
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> triangles;
    std::vector<openvdb::Vec4I> quads;
    openvdb::tools::volumeToMesh(grid, points, triangles, quads, 0.0, adaptivity);
    Mesh mesh;
    mesh.positions.reserve(points.size());
    for (const auto& p : points) mesh.positions.emplace_back(p.x(), p.y(), p.z());
    mesh.triangles.reserve(triangles.size() + 2 * quads.size());
    for (const auto& t : triangles) mesh.triangles.push_back({t[0], t[1], t[2]});
    for (const auto& q : quads) appendQuad(points, q, mesh.triangles);
    return mesh;
}

}  // namespace

Mesh VdbSurface::build(const sim::FrameView& frame, const RenderSettings& settings) {
    openvdb::FloatGrid::Ptr grid = rasterize(frame.positions, voxelSize_, radius_, dropped_);
    smooth(*grid, smoothingIterations_);
    Mesh mesh = zeroCrossing(*grid, adaptivity_);
    orientOutward(mesh);
    mesh.normals = areaWeightedNormals(mesh);
    // Every surface point lies about one radius from its nearest particle, so cells of two
    // radii find it in the first ring of cells (cells of one radius needed a second ring, 5x
    // the lookups, for most vertices).
    nearestParticleColors(frame, settings, mesh, 2.0 * radius_);
    grid_ = std::make_unique<Grid>(Grid{std::move(grid)});
    return mesh;
}

std::uint64_t VdbSurface::activeVoxelCount() const {
    return grid_ ? grid_->levelSet->activeVoxelCount() : 0;
}

VdbFileInfo inspectVdb(const std::filesystem::path& path) {
    vdb::initialize();
    try {
        openvdb::io::File file(path.string());
        file.open();
        VdbFileInfo info;
        openvdb::GridPtrVecPtr grids = file.getGrids();
        info.gridCount = grids->size();
        for (const openvdb::GridBase::Ptr& grid : *grids) {
            info.gridNames.push_back(grid->getName());
            info.activeVoxels.push_back(grid->activeVoxelCount());
            std::array<float, 2> range{0.0f, 0.0f};
            if (const auto floats = openvdb::gridPtrCast<openvdb::FloatGrid>(grid)) {
                range = {std::numeric_limits<float>::max(), std::numeric_limits<float>::lowest()};
                for (auto v = floats->cbeginValueOn(); v; ++v)
                    range = {std::min(range[0], *v), std::max(range[1], *v)};
            }
            info.range.push_back(range);
        }
        if (!grids->empty()) {
            const openvdb::GridBase::Ptr& first = grids->front();
            info.firstGridName = first->getName();
            info.firstGridActiveVoxels = first->activeVoxelCount();
            info.firstGridVoxelSize = first->voxelSize()[0];
        }
        file.close();
        return info;
    } catch (const openvdb::Exception& e) {
        throw std::runtime_error("cannot read " + path.string() + ": " + e.what());
    }
}

}  // namespace rend::render
