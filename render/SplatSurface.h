#pragma once
// The `splat` surface: one oriented disc per particle, sized from the rest lattice so that
// neighbouring discs overlap, and oriented by the particle's current neighbourhood. It needs
// no connectivity at render time, so it shows fragments, dust and a torn sheet alike.

#include <array>
#include <cstdint>
#include <vector>

#include "render/Mesh.h"
#include "render/RenderSettings.h"
#include "render/Splats.h"
#include "sim/FrameView.h"

namespace rend::render {

/// Mean nearest-neighbour distance of the rest lattice (shortest bond per particle, or shortest
/// rest-triangle edge where a particle has no bond); 0 when neither exists. Surfaces size their
/// features from it so that a scene's dx never has to be repeated in the render settings.
double restSpacing(const sim::FrameView& rest);

/// Normals: the area-weighted normal of the particle's incident rest triangles, with current
/// positions, skipping triangles that have a broken edge bond. Rest triangles are
/// counter-clockwise seen from +z, so this normal is on the rest lattice's +z side however
/// the sheet has folded. Where no triangle remains, the smallest principal axis of the
/// particle and its intact-bond neighbours (PCA), turned to agree with the nearest neighbour
/// that still has a triangle normal, else with +z; (0, 0, 1) for an isolated particle.
class SplatSurface {
public:
    /// Precomputes each particle's incident triangles and the disc radius. Throws
    /// std::invalid_argument when the rest lattice has no bond and no triangle (nothing to size
    /// discs from).
    explicit SplatSurface(const sim::FrameView& rest);

    Splats build(const sim::FrameView& frame, const RenderSettings& settings) const;

    /// The disc radius used for every particle [m].
    double radius() const { return radius_; }

    /// Per rest triangle, 1 where the frame keeps it (FrameView::keptTriangles): the discs'
    /// normals come from these.
    std::vector<std::uint8_t> keptTriangles(const sim::FrameView& frame) const;

private:
    /// Sum of the kept incident triangles' doubled-area normals; zero when none is kept.
    Eigen::Vector3d triangleNormal(const sim::FrameView& frame,
                                   const std::vector<std::uint8_t>& kept, int particle) const;
    Eigen::Vector3f fallbackNormal(const sim::FrameView& frame,
                                   const std::vector<Eigen::Vector3f>& normals,
                                   const std::vector<std::uint8_t>& fromTriangles,
                                   int particle) const;

    std::vector<std::array<int, 3>> triangles_;
    /// Triangles incident to particle i: incident_[incidentOffsets_[i] .. [i + 1]).
    std::vector<int> incidentOffsets_;
    std::vector<int> incident_;
    double radius_ = 0.0;
};

/// Each disc as a fan of `segments` triangles around its centre, so that the rasterizer and
/// the mesh exporters can take splats. The polygon circumscribes the disc (its rim vertices lie
/// at radius / cos(pi / segments)), so it covers at least the disc and a flat sheet stays
/// free of gaps. Vertices per disc: centre first, then the rim. Throws std::invalid_argument
/// for segments < 3.
Mesh splatsToMesh(const Splats& splats, int segments = 6);

}  // namespace rend::render
