#pragma once
// Triangle meshes for mesh colliders (sim/Collider.h), read through assimp: OBJ, PLY, glTF and
// GLB, or any other format the installed assimp reads.

#include <cstddef>
#include <filesystem>

#include "sim/Collider.h"

namespace rend::render {

/// Every triangle of every mesh in `file`, node transforms applied, joined into one mesh and
/// multiplied by `scale`. OBJ, glTF and GLB are y up and are turned into rend's z-up world
/// ((x, y, z) -> (x, -z, y), as Blender's importers do); PLY and other formats are taken as
/// they are. The collider needs positions only, so vertices at the same position
/// are one vertex even where the file splits them by normal or texture coordinate (a cube's
/// corners in an OBJ with `vn` lines), and triangles that this leaves degenerate are dropped.
/// Polygons are triangulated; points and lines are ignored. Throws std::runtime_error naming the
/// file when it is missing, assimp cannot read it, or it holds no triangles; std::invalid_argument
/// for a scale that is not positive and finite.
sim::TriangleMesh importTriangleMesh(const std::filesystem::path& file, double scale = 1.0);

/// The edges not shared by exactly two triangles: 0 for a closed mesh, which is what the
/// simulator needs to tell inside from outside. Counts the holes' rims and non-manifold edges.
std::size_t openEdgeCount(const sim::TriangleMesh& mesh);

inline bool isClosed(const sim::TriangleMesh& mesh) { return openEdgeCount(mesh) == 0; }

}  // namespace rend::render
