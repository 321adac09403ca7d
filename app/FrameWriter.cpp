#include "app/FrameWriter.h"

#include <chrono>
#include <cstdio>

#include "app/Pipeline.h"
#include "app/SceneError.h"
#include "render/ColliderMesh.h"
#include "render/EmbreeRenderer.h"
#include "render/ExrWriter.h"
#include "render/LatticeSurface.h"
#include "render/MeshExport.h"
#include "render/OsmesaRenderer.h"
#include "render/SheetVolume.h"
#include "render/SplatSurface.h"
#include "render/VdbSurface.h"

namespace rend {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string frameName(int frame, const char* extension) {
    char name[40];
    std::snprintf(name, sizeof name, "frame_%04d.%s", frame, extension);
    return name;
}

// Folder and extension of each export format, in ExportFormat's order.
constexpr std::pair<const char*, const char*> kExportFiles[] = {
    {"meshes/", "ply"}, {"meshes/", "obj"}, {"meshes/", "glb"}, {"vdb/", "vdb"}};

std::string exportName(int frame, ExportFormat format) {
    const auto& [folder, extension] = kExportFiles[int(format)];
    return folder + frameName(frame, extension);
}

const render::Mesh& asMesh(const render::Geometry& geometry, render::Mesh& scratch) {
    if (const auto* mesh = std::get_if<render::Mesh>(&geometry)) return *mesh;
    scratch = render::splatsToMesh(std::get<render::Splats>(geometry));
    return scratch;
}

}  // namespace

struct FrameWriter::Parts {
    std::unique_ptr<render::LatticeSurface> lattice;
    std::unique_ptr<render::LatticeSurface> levelSet;  ///< particle_level_set
    std::unique_ptr<render::SplatSurface> splat;
    std::unique_ptr<render::VdbSurface> vdb;
    double exportVoxel = 0.0;  ///< the exported volume's, resolved on its first frame
    std::unique_ptr<render::OsmesaRenderer> osmesa;
    std::unique_ptr<render::EmbreeRenderer> embree;
    /// The last frame's surface: a mesh is built into it again, its arrays' storage kept (the
    /// final foil's 50 MB, zeroed by the kernel in fresh pages each frame before).
    render::Geometry geometry;
};

FrameWriter::FrameWriter(const Scene& scene, const std::filesystem::path& outDir)
    : scene_(scene), outDir_(outDir), parts_(std::make_unique<Parts>()) {
    if (scene.writeExr && scene.renderer == RendererKind::Osmesa) {
        throw SceneError(scene.locationOf("output.exr") +
                         ": error: output.exr: expected the path tracer, found the osmesa "
                         "renderer, whose frames have no linear radiance or first-hit layers. "
                         "Use --renderer embree, or set exr = false.");
    }
}

FrameWriter::~FrameWriter() = default;

bool FrameWriter::active() const {
    return scene_.renderer != RendererKind::None || !scene_.exports.empty();
}

std::vector<std::string> FrameWriter::plannedFiles(int frame) const {
    std::vector<std::string> names;
    if (scene_.renderer != RendererKind::None) names.push_back("frames/" + frameName(frame, "png"));
    if (writesExr()) names.push_back("frames/" + frameName(frame, "exr"));
    for (ExportFormat format : scene_.exports) {
        names.push_back(exportName(frame, format));
        if (format == ExportFormat::Obj) names.push_back("meshes/" + frameName(frame, "mtl"));
    }
    return names;
}

const render::Geometry& FrameWriter::buildSurface(const sim::FrameView& view) {
    Parts& p = *parts_;
    switch (scene_.render.surface) {
        case render::SurfaceKind::Splat:
            if (!p.splat) p.splat = std::make_unique<render::SplatSurface>(view);
            return p.geometry = p.splat->build(view, scene_.render);
        case render::SurfaceKind::Vdb:
            if (!p.vdb) p.vdb = std::make_unique<render::VdbSurface>(view, scene_.render.vdb);
            return p.geometry = p.vdb->build(view, scene_.render);
        case render::SurfaceKind::ParticleLevelSet:
        case render::SurfaceKind::Lattice:
            break;
    }
    render::LatticeSurface& surface = meshSurface(view);
    if (!std::holds_alternative<render::Mesh>(p.geometry)) p.geometry = render::Mesh{};
    surface.build(view, scene_.render, std::get<render::Mesh>(p.geometry));
    return p.geometry;
}

render::LatticeSurface& FrameWriter::meshSurface(const sim::FrameView& view) {
    Parts& p = *parts_;
    if (scene_.render.surface == render::SurfaceKind::ParticleLevelSet) {
        if (!p.levelSet)
            p.levelSet = std::make_unique<render::LatticeSurface>(
                view, render::LatticeSurface::Outline::LevelSet);
        return *p.levelSet;
    }
    if (!p.lattice) p.lattice = std::make_unique<render::LatticeSurface>(view);
    return *p.lattice;
}

bool FrameWriter::writesExr() const {
    return scene_.writeExr && scene_.renderer == RendererKind::Embree;
}

render::Image FrameWriter::renderImage(const sim::FrameView& view, const render::Geometry& geometry,
                                       render::FrameLayers* layers) {
    Parts& p = *parts_;
    const std::vector<render::Mesh> colliders = render::colliderMeshes(view);
    if (scene_.renderer == RendererKind::Embree) {
        if (!p.embree) p.embree = std::make_unique<render::EmbreeRenderer>();
        return p.embree->render(geometry, scene_.render, layers, colliders);
    }
    if (!p.osmesa) p.osmesa = std::make_unique<render::OsmesaRenderer>();
    render::Mesh scratch;
    return p.osmesa->render(asMesh(geometry, scratch), scene_.render, colliders);
}

const render::Mesh& FrameWriter::midSurface(const sim::FrameView& view,
                                            const render::Geometry& geometry,
                                            render::Mesh& scratch) {
    const bool meshes = scene_.render.surface == render::SurfaceKind::Lattice ||
                        scene_.render.surface == render::SurfaceKind::ParticleLevelSet;
    if (meshes && scene_.render.thickness == 0.0) return std::get<render::Mesh>(geometry);
    render::RenderSettings flat = scene_.render;
    flat.thickness = 0.0;
    scratch = meshSurface(view).build(view, flat);
    return scratch;
}

void FrameWriter::exportFrame(const sim::FrameView& view, const render::Geometry& geometry,
                              std::vector<std::string>& written) {
    render::Mesh scratch;
    for (ExportFormat format : scene_.exports) {
        const std::string name = exportName(view.frame, format);
        const std::filesystem::path path = outDir_ / name;
        std::filesystem::create_directories(path.parent_path());
        if (format == ExportFormat::Vdb) {
            // [render] vdb_voxel_size, or half the rest spacing as for the vdb surface.
            double& voxel = parts_->exportVoxel;
            if (voxel == 0.0) voxel = scene_.render.vdb.voxelSize;
            if (voxel == 0.0) voxel = 0.5 * render::restSpacing(view);
            render::Mesh mid;
            lastVolume_ = render::writeSheetVolume(midSurface(view, geometry, mid), view.theta,
                                                   voxel, scene_.sim.sheet.thickness, path);
            written.push_back(name);
            continue;
        }
        const std::string folder = kExportFiles[int(format)].first;
        for (const std::filesystem::path& file :
             render::exportMesh(asMesh(geometry, scratch), path, render::MeshFormat(int(format))))
            written.push_back(folder + file.filename().string());
    }
}

void FrameWriter::write(const sim::FrameView& view, StageTimes& seconds,
                        std::vector<std::string>& written) {
    if (!active()) return;
    auto t0 = Clock::now();
    const render::Geometry& geometry = buildSurface(view);
    seconds.surface += secondsSince(t0);
    if (scene_.renderer != RendererKind::None) {
        t0 = Clock::now();
        render::FrameLayers layers;
        const render::Image image = renderImage(view, geometry, writesExr() ? &layers : nullptr);
        seconds.render += secondsSince(t0);
        t0 = Clock::now();
        std::filesystem::create_directories(outDir_ / "frames");
        const std::string name = "frames/" + frameName(view.frame, "png");
        render::writePngAtomic(image, outDir_ / name);
        written.push_back(name);
        if (writesExr()) {
            const std::string exr = "frames/" + frameName(view.frame, "exr");
            render::writeExrAtomic(layers, outDir_ / exr);
            written.push_back(exr);
        }
        seconds.write += secondsSince(t0);
    }
    t0 = Clock::now();
    exportFrame(view, geometry, written);
    seconds.write += secondsSince(t0);
}

}  // namespace rend
