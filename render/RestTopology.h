#pragma once
// Rest-lattice connectivity that surfaces share, computed once: the triangles around every
// particle, the lattice edges with their triangles, and the notches of the rest outline. Which
// triangles a frame keeps is FrameView::keptTriangles.

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "sim/FrameView.h"

namespace rend::render {

/// Triangles around each of `vertexCount` particles in CSR form: those of particle v are
/// incident[offsets[v] .. offsets[v+1]), in ascending triangle order (a counting sort).
void incidentTriangles(const std::vector<std::array<int, 3>>& triangles, std::size_t vertexCount,
                       std::vector<int>& offsets, std::vector<int>& incident);

/// The edges of the rest triangles. Side k of a triangle joins its corners k and k + 1.
struct RestEdges {
    std::vector<std::array<int, 2>> ends;        ///< {i, j}, i < j, in order of first use
    std::vector<std::array<int, 2>> triangles;   ///< the one or two triangles; -1 for none
    std::vector<std::array<int, 3>> ofTriangle;  ///< edge of each side of each triangle
    std::vector<std::array<int, 3>> neighbours;  ///< triangle across each side, or -1

    /// The other triangle on edge `e` than `t`, or -1.
    int across(int e, int t) const {
        return triangles[e][0] == t ? triangles[e][1] : triangles[e][0];
    }
};

/// Pairs every side with the triangle across it. The rest lattice is a planar (or closed)
/// triangulation, so an edge has at most two triangles; a third (never produced by sim/) is
/// left unpaired rather than guessed at.
RestEdges restEdges(const std::vector<std::array<int, 3>>& triangles);

/// Where the rest outline zig-zags, the notch particles and the chord they move to. A hexagonal
/// lattice cut to a rectangle has its odd rows shifted by dx/2, so the sides alternate between
/// particles on the rectangle's side and particles dx/2 inside it. Each inside one (a shallow
/// concave corner of the outline: an angle of more than ~107 degrees between its two outline
/// edges, walked outside the sheet) is given the midpoint of its two outline neighbours, which
/// lies on the side: a rectangle's outline becomes straight. Returns, per particle, those two
/// neighbours {p, n}, or {-1, -1} where the particle stays put. Real corners (90 degrees and
/// sharper) are left alone.
std::vector<std::array<int, 2>> outlineNotches(const std::vector<std::array<int, 3>>& triangles,
                                               const RestEdges& edges,
                                               std::span<const Eigen::Vector3d> rest);

}  // namespace rend::render
