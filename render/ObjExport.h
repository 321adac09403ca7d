#pragma once
// OBJ + MTL written here rather than through assimp: assimp 5.2's OBJ exporter shares vertices
// whose position, normal and colour are equal, which joins a crack's two lips (they coincide
// until it opens) and the copies a lattice surface makes at a bow-tie, so Blender found fewer
// loose parts in the OBJ than in the PLY of the same frame. Here vertex i is the mesh's vertex
// i, every one written, used or not, so the particles keep their indices as in the PLY.

#include <filesystem>
#include <vector>

#include "render/Mesh.h"

namespace rend::render {

/// Writes `path` (.obj) and its .mtl beside it, the .mtl first, each atomically; returns both,
/// `path` last. Throws std::system_error naming the file; leaves no .mtl without its .obj.
std::vector<std::filesystem::path> writeObj(const Mesh& mesh, const std::filesystem::path& path);

}  // namespace rend::render
