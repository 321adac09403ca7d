#pragma once
// Writes a render Mesh to a file another tool can open: binary PLY (point-cloud and geometry
// tools), OBJ + MTL (everything), GLB (web viewers, Blender). All three are written directly,
// not through assimp: assimp 5.2's binary PLY exporter corrupts files that have vertex colours
// (see MeshExport.cpp), its OBJ exporter joins coincident vertices (render/ObjExport.h), and
// its glTF exporter drops unused vertices and writes no custom attribute (render/GlbExport.h).
// In every format vertex i is the mesh's vertex i.

#include <filesystem>
#include <string_view>
#include <vector>

#include "render/Mesh.h"

namespace rend::render {

enum class MeshFormat { Ply, Obj, Glb };

/// "ply", "obj" or "glb" (case-insensitive, an optional leading dot allowed); throws
/// std::invalid_argument naming the accepted values otherwise.
MeshFormat parseMeshFormat(std::string_view name);

/// The usual file extension of a format, with the dot (".ply", ".obj", ".glb").
std::string_view meshFormatExtension(MeshFormat format);

/// rend's world (z up, as Blender's) in the y-up frame of glTF (its rule) and OBJ (the
/// convention Blender's, Maya's and Houdini's importers assume): (x, y, z) -> (x, z, -y), a
/// rotation, so importers that convert y-up to z-up give back rend's coordinates exactly.
inline Eigen::Vector3f toYUp(const Eigen::Vector3f& p) { return {p.x(), p.z(), -p.y()}; }

/// Each vertex's rest position (Mesh::points) in [0, 1]^2 over the rest bounds of the mesh's
/// vertices: a UV map that stays put on the sheet from frame to frame. Empty without points.
std::vector<Eigen::Vector2f> restUv(const Mesh& mesh);

/// Writes positions, triangles, per-vertex normals and colours: GLB as linear COLOR_0 (glTF's
/// convention), PLY as 8-bit red/green/blue encoded with gamma 1/2.2 (viewers show PLY bytes
/// as sRGB), OBJ only as the non-standard "v x y z r g b" extension. The files (OBJ's .mtl too)
/// are encoded in memory and written with writeFileAtomic (render/AtomicFile.h) next to `path`,
/// the main file last, so a reader never sees a half-written file nor an OBJ whose material
/// library is missing. Returns the files written, `path` last. Throws std::system_error naming
/// the file and the reason when a write fails; a file that failed is not left behind.
std::vector<std::filesystem::path> exportMesh(const Mesh& mesh, const std::filesystem::path& path,
                                              MeshFormat format);

}  // namespace rend::render
