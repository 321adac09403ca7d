#pragma once
// The `lattice` surface: the rest lattice triangulated once (FrameView::restTriangles);
// per frame a triangle is dropped when the bond along one of its edges is broken.

#include <array>
#include <vector>

#include "render/Mesh.h"
#include "render/RenderSettings.h"
#include "sim/FrameView.h"

namespace rend::render {

class LatticeSurface {
public:
    /// Maps every rest triangle's edges to bond indices once. An edge that is not a bond
    /// (a square lattice with R < sqrt(2) dx has no diagonal bonds) never drops its triangle.
    explicit LatticeSurface(const sim::FrameView& rest);

    /// Triangles whose three edge bonds are intact, with smooth (area-weighted) normals and
    /// per-vertex colours from the settings' ColorBy.
    Mesh build(const sim::FrameView& frame, const RenderSettings& settings) const;

    /// Indices into FrameView::restTriangles of the triangles kept in this frame.
    std::vector<int> keptTriangles(const sim::FrameView& frame) const;

private:
    std::vector<std::array<int, 3>> triangles_;
    std::vector<std::array<int, 3>> edgeBonds_;  ///< bond index per edge (i->j), -1 if none
};

}  // namespace rend::render
