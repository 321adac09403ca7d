#pragma once
// The `lattice` surface: the rest lattice triangulated once (FrameView::restTriangles) and cut,
// per frame, along the lattice edges whose bonds broke, as marching triangles cut a triangle
// along an iso-line: each broken edge gets a crossing point, and each triangle is split into the
// pieces on either side of the crack through it. So cracks are cut where the bonds broke, with
// smooth lips that open as the particles separate, instead of dropping whole triangles.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "render/Mesh.h"
#include "render/RenderSettings.h"
#include "render/RestTopology.h"
#include "sim/FrameView.h"

namespace rend::render {

/// The cut. A lattice edge is *broken* when its bond (FrameView::bondAlive) is. Each broken edge
/// has a crossing point in rest coordinates, first its midpoint, then moved along the edge to
/// where the crack's line through its two neighbouring crossing points meets it (four Jacobi
/// passes; at the sheet's outline or the crack's tip, the line through the next two): a straight
/// crack gives a straight cut whatever its angle to the lattice, where the midpoints alone
/// zig-zag at the lattice spacing. Per triangle, by its number of broken sides:
/// - none: kept whole;
/// - one (the crack's tip, or a lone broken bond): a slit from the crossing point to the
///   centroid; the triangle stays one piece, so a lone broken bond leaves no hole;
/// - two: the corner between them becomes a triangle, the other two corners a quad;
/// - three (a crack junction): three quads, one per corner, meeting at the centroid.
/// Every crossing point has two vertices, one for each end of its edge, and each piece takes
/// the one of its own corner, so the two lips of a crack are separate and no triangle bridges
/// it. A lip vertex lies at its rest distance from its particle, towards the other end and in
/// its particle's tangent plane, so a lip keeps the particle's side's shape and the crack opens
/// by exactly how far the particles moved apart beyond their rest length. Pieces connect
/// exactly where lattice edges are intact, so a fully separated sheet falls into pieces.
///
/// Triangles that FrameView::keptTriangles drops with no broken side (the FEM's element
/// erosion) or that FrameView::triangleAlive says were removed are dropped whole. Around each
/// particle the remaining triangles fall into *fans* connected through shared sides; the first
/// fan (the one holding the particle's lowest-numbered triangle) uses the particle's own
/// vertex, every further fan a copy, so two pieces touching at one particle (a bowtie) share no
/// vertex. A cut never splits a fan: around a particle, consecutive pieces always share at
/// least the half of their common edge on the particle's side.
///
/// The outline: notch particles of the rest outline (RestTopology's outlineNotches) are drawn
/// at the midpoint of their two outline neighbours while both outline bonds hold, so an intact
/// rectangle of hexagonal lattice has straight sides. Vertices [0, particleCount) are the
/// particles, in order (at the particles' positions but for those notches); fan copies, lip
/// vertices and centroids follow. An intact sheet has no extra vertex.
///
/// Everything per frame is a pass over the triangles and edges: O(triangles).
///
/// The `particle_level_set` surface (issue 15, seed 004) is this one with its outline drawn by
/// the particle level set of FrameView (sim/ParticleLevelSet.h) instead of the notches: each
/// kept band triangle (particles and ghosts) is cut at Phi = 0 by marching triangles, and its
/// inside part (a triangle or a quad: the particles, and the crossing points on its
/// particle-ghost edges) is added to the mesh, sharing the particles' vertices. A crossing
/// vertex carries its particle's data, at the rest point of the crossing. The sheet then ends
/// on the scene's outline (a rectangle's straight sides, a disc's circle) instead of on its
/// outermost particles, and moves with the ghosts. Crack lips are the cut's above: their
/// vertices lie half a rest bond from their particle, which is where the level set puts a
/// crack's zero points. Without ghosts (a sphere) it is the lattice surface without notches.
class LatticeSurface {
public:
    enum class Outline { Notches, LevelSet };

    /// Builds the edge maps, the triangles around each particle and the outline notches once.
    explicit LatticeSurface(const sim::FrameView& rest, Outline outline = Outline::Notches);

    /// The frame's mesh (cut as above), smooth (area-weighted) normals per vertex, which never
    /// blend across a crack, and per-vertex colours from the settings' ColorBy, interpolated
    /// along the edge at lip vertices and averaged at centroids.
    ///
    /// With settings.thickness > 0 the sheet becomes a solid: the mesh above, offset by
    /// +thickness/2 along the vertex normals (same vertex indices, so vertices
    /// [0, particleCount) are still the particles), a copy offset by -thickness/2 facing the
    /// other way (indices + the sheet's vertex count), then walls along every edge used by a
    /// single triangle, with their own vertices and outward normals, so the outline and both
    /// lips of every crack show as walls. Welding coincident vertices makes it closed.
    /// Large thicknesses on sharply folded sheets self-intersect: it is an offset, not a CSG.
    Mesh build(const sim::FrameView& frame, const RenderSettings& settings) const;
    /// The same mesh into `mesh`, whose arrays keep their storage: a shot's frames build into
    /// the last frame's mesh rather than fresh pages each time.
    void build(const sim::FrameView& frame, const RenderSettings& settings, Mesh& mesh) const;

    /// Indices into FrameView::restTriangles of the triangles kept in this frame
    /// (FrameView::keptTriangles: none of their sides broken, not removed).
    std::vector<int> keptTriangles(const sim::FrameView& frame) const;

private:
    struct Cuts;
    struct Corners {
        std::vector<std::array<std::uint32_t, 3>> vertex;  ///< per rest triangle
        std::vector<int> copyOf;                           ///< particle of vertex particleCount + k
    };
    class Builder;

    class Placed;
    Cuts findCuts(const sim::FrameView& frame) const;
    void placeCrossings(const Placed& placed, Cuts& cuts) const;
    Corners splitFans(const std::vector<std::uint8_t>& present, std::size_t particleCount) const;
    void walkFan(int start, int particle, std::uint32_t vertex,
                 const std::vector<std::uint8_t>& present, Corners& corners,
                 std::vector<int>& stack) const;
    int cornerOf(int triangle, int particle) const;

    Outline outline_ = Outline::Notches;
    std::vector<std::array<int, 3>> triangles_;
    RestEdges edges_;
    std::vector<int> edgeBond_;  ///< bond ends[0] -> ends[1] of each edge, or -1
    /// An outline notch: the particle, its outline neighbours and the bonds to them.
    struct Notch {
        int particle, p, n, bondP, bondN;
    };
    std::vector<Notch> notches_;
    std::vector<int> notchOf_;  ///< per particle: its index in notches_, or -1
    std::vector<Eigen::Vector3d> rest_;
    std::vector<Eigen::Vector3d> restNormal_;  ///< unit, area-weighted over the rest triangles
    /// Triangles incident to particle i: incident_[incidentOffsets_[i] .. [i + 1]), ascending.
    std::vector<int> incidentOffsets_;
    std::vector<int> incident_;
};

}  // namespace rend::render
