#pragma once
// Headless rasterized preview through OSMesa (no display): the scene's camera, a directional
// light plus ambient, two-sided shading, a ground plane.

#include <memory>
#include <span>
#include <string>

#include "render/Image.h"
#include "render/Mesh.h"
#include "render/RenderSettings.h"

namespace rend::render {

class OsmesaRenderer {
public:
    OsmesaRenderer();  ///< creates the off-screen context; throws if OSMesa is unusable
    ~OsmesaRenderer();
    OsmesaRenderer(const OsmesaRenderer&) = delete;
    OsmesaRenderer& operator=(const OsmesaRenderer&) = delete;

    /// `colliders`: world-space meshes (colliderMeshes in render/ColliderMesh.h), index for index
    /// with RenderSettings::colliderLooks, shaded in their looks' colours.
    Image render(const Mesh& mesh, const RenderSettings& settings,
                 std::span<const Mesh> colliders = {});

    /// GL_RENDERER and GL_VERSION of the context, e.g. "llvmpipe (LLVM 15.0.6, 256 bits), 4.5".
    std::string glDescription();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace rend::render
