#pragma once
// A small path tracer on Embree 3: the OSMesa preview's camera and output encoding, a sky (or
// constant background) environment, a soft sun with next-event estimation, an analytic ground
// plane, and the membrane materials of PathTracing (diffuse, GGX conductor, film, translucent).
// Meshes are traced as triangles, splats as oriented discs. Pixels are deterministic: every
// random number is a hash of (pixel, sample, dimension), so any thread count gives the same
// bytes.

#include <memory>
#include <span>
#include <string>

#include "render/ExrWriter.h"
#include "render/Geometry.h"
#include "render/Image.h"
#include "render/RenderSettings.h"

namespace rend::render {

class EmbreeRenderer {
public:
    EmbreeRenderer();  ///< creates the Embree device; throws std::runtime_error on failure
    ~EmbreeRenderer();
    EmbreeRenderer(const EmbreeRenderer&) = delete;
    EmbreeRenderer& operator=(const EmbreeRenderer&) = delete;

    /// Renders one frame. A frame with the same topology as the previous call (same geometry
    /// kind, same triangle indices or disc count) only refits the BVH. Throws
    /// std::invalid_argument for inconsistent geometry or a non-positive image size. With
    /// `layers`, also fills its linear radiance and the first-hit depth, normal and theta of
    /// each pixel's centre ray (for writeExrAtomic). `colliders`: world-space meshes
    /// (colliderMeshes in render/ColliderMesh.h), index for index with
    /// RenderSettings::colliderLooks; they cast and receive shadows, and their theta is 0.
    Image render(const Geometry& geometry, const RenderSettings& settings,
                 FrameLayers* layers = nullptr, std::span<const Mesh> colliders = {});

    /// The Embree version actually loaded, e.g. "Embree 3.13.5".
    std::string deviceDescription();

    /// Rays (camera, bounce and shadow) traced by the last render(), for rays per second.
    long long raysTraced() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace rend::render
