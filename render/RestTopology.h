#pragma once
// Rest-lattice connectivity that surfaces share, computed once: the triangles around every
// particle. Which triangles a frame keeps is FrameView::keptTriangles.

#include <array>
#include <cstddef>
#include <vector>

#include "sim/FrameView.h"

namespace rend::render {

/// Triangles around each of `vertexCount` particles in CSR form: those of particle v are
/// incident[offsets[v] .. offsets[v+1]), in ascending triangle order (a counting sort).
void incidentTriangles(const std::vector<std::array<int, 3>>& triangles, std::size_t vertexCount,
                       std::vector<int>& offsets, std::vector<int>& incident);

}  // namespace rend::render
