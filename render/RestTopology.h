#pragma once
// Rest-lattice connectivity that surfaces share, computed once: the bond along every triangle
// edge and the triangles around every particle.

#include <array>
#include <cstddef>
#include <vector>

#include "sim/FrameView.h"

namespace rend::render {

/// Bond index of each triangle edge (t[0]->t[1], t[1]->t[2], t[2]->t[0]); -1 where the edge is
/// not a bond (a square lattice with R < sqrt(2) dx has no diagonal bonds).
std::vector<std::array<int, 3>> triangleEdgeBonds(const sim::FrameView& rest,
                                                  const std::vector<std::array<int, 3>>& triangles);

/// Triangles around each of `vertexCount` particles in CSR form: those of particle v are
/// incident[offsets[v] .. offsets[v+1]), in ascending triangle order (a counting sort).
void incidentTriangles(const std::vector<std::array<int, 3>>& triangles, std::size_t vertexCount,
                       std::vector<int>& offsets, std::vector<int>& incident);

}  // namespace rend::render
