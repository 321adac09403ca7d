#pragma once
// The edges of a triangle list, numbered once at set-up for the damage state's maps
// (sim/DamageState.h) and the lattice surface's cut (render/RestTopology.h).

#include <array>
#include <cstddef>
#include <span>
#include <vector>

namespace rend::sim {

/// An edge is an unordered pair of corners; a side's edge is the same whichever way round the
/// side runs. Edges are numbered in order of first use: triangle by triangle, and within one its
/// sides in order, side s running from corner (s + firstCorner) % 3 to the next.
struct TriangleEdges {
    std::vector<std::array<int, 2>> ends;        ///< {i, j}, i <= j
    std::vector<std::array<int, 3>> ofTriangle;  ///< the edge of each side of each triangle
};

/// Found among the edges already numbered from a side's lower corner (a few each on a
/// lattice), not a map of every pair: 576,423 triangles (a 289,289-particle sheet) took
/// 0.04-0.06 s through the triangles around each corner, where inserting their sides into a
/// std::map alone took 0.13-0.19 s; by the numbered edges, 1,450 -> 150 instructions a particle
/// (the final foil's 502,000 triangles). Corners must be non-negative.
TriangleEdges triangleEdges(std::span<const std::array<int, 3>> triangles, int firstCorner);

/// The triangles at each corner v < cornerCount, ascending: at[offsets[v] .. offsets[v + 1]).
void trianglesAtCorners(std::span<const std::array<int, 3>> triangles, std::size_t cornerCount,
                        std::vector<int>& offsets, std::vector<int>& at);

}  // namespace rend::sim
