#pragma once
// The `lattice` surface: the rest lattice triangulated once (FrameView::restTriangles);
// per frame a triangle is dropped when the bond along one of its edges is broken, and the
// vertices along cracks are duplicated so that the surface opens there.

#include <array>
#include <cstdint>
#include <vector>

#include "render/Mesh.h"
#include "render/RenderSettings.h"
#include "sim/FrameView.h"

namespace rend::render {

/// Vertex duplication along cracks. Around each particle, its kept triangles fall into *fans*:
/// groups connected through shared edges (two kept triangles that share an edge share an
/// intact bond, so they belong to the same piece of material there). The first fan (the one
/// holding the particle's lowest-numbered kept triangle) uses the particle's own vertex; every
/// further fan gets a copy with the same position and colour. Normals are averaged per vertex,
/// so they never blend across a crack, and two fragments touching at one particle (a bowtie)
/// share no vertex. Vertices [0, particleCount) are the particles, in order, so an intact
/// sheet gives exactly the mesh it gave before cracks were handled; copies follow.
///
/// The per-particle triangle lists and the triangle-edge adjacency are built once; a frame
/// only recomputes which triangles are kept and walks each particle's fans: O(triangles).
class LatticeSurface {
public:
    /// Builds the triangles around each particle and the edge adjacency once.
    explicit LatticeSurface(const sim::FrameView& rest);

    /// The frame's kept triangles (FrameView::keptTriangles), with vertices duplicated along
    /// cracks (see above), smooth (area-weighted) normals per vertex and per-vertex colours from
    /// the settings' ColorBy.
    ///
    /// With settings.thickness > 0 the sheet becomes a solid: the mesh above, offset by
    /// +thickness/2 along the vertex normals (same vertex indices, so vertices
    /// [0, particleCount) are still the particles), a copy offset by -thickness/2 facing the
    /// other way (indices + the sheet's vertex count), then walls along every edge used by a
    /// single kept triangle, with their own vertices and outward normals, so the outline and
    /// both lips of every crack show as walls. Welding coincident vertices makes it closed.
    /// Large thicknesses on sharply folded sheets self-intersect: it is an offset, not a CSG.
    Mesh build(const sim::FrameView& frame, const RenderSettings& settings) const;

    /// Indices into FrameView::restTriangles of the triangles kept in this frame.
    std::vector<int> keptTriangles(const sim::FrameView& frame) const;

private:
    /// A triangle's mesh vertex per corner, plus the particle each appended copy stands for.
    struct Corners {
        std::vector<std::array<std::uint32_t, 3>> vertex;  ///< per rest triangle
        std::vector<int> copyOf;                           ///< particle of vertex particleCount + k
    };

    std::vector<std::uint8_t> keptFlags(const sim::FrameView& frame) const;
    Corners splitFans(const std::vector<std::uint8_t>& kept, std::size_t particleCount) const;
    void walkFan(int start, int particle, std::uint32_t vertex,
                 const std::vector<std::uint8_t>& kept, Corners& corners,
                 std::vector<int>& stack) const;
    int cornerOf(int triangle, int particle) const;

    std::vector<std::array<int, 3>> triangles_;
    /// Triangle across edge e (corners e, e+1) of each triangle; -1 on the rest boundary.
    std::vector<std::array<int, 3>> edgeNeighbours_;
    /// Triangles incident to particle i: incident_[incidentOffsets_[i] .. [i + 1]), ascending.
    std::vector<int> incidentOffsets_;
    std::vector<int> incident_;
};

}  // namespace rend::render
