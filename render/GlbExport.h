#pragma once
// Binary glTF 2.0 (.glb) written here rather than through assimp: assimp 5.2 runs
// JoinIdenticalVertices before its glTF exporter whatever the caller asks, which drops the
// particles no triangle holds any more, renumbers the rest, and may join a crack's two lips; and
// it writes no custom attribute. Here vertex i is the mesh's vertex i, every one written, with
// POSITION, NORMAL, COLOR_0 (linear), TEXCOORD_0 (the rest UV, glTF's v pointing down) and
// the application-specific attributes `_ID`, `_VELOCITY`, `_DAMAGE`, `_REST` and `_THETA`
// (glTF asks custom names to start with an underscore). `_ID` is a float, exact to 2^24
// particles: glTF allows unsigned 32-bit integers for indices only.

#include <filesystem>
#include <string>
#include <vector>

#include "render/Mesh.h"

namespace rend::render {

/// The whole .glb file's bytes.
std::string glbBytes(const Mesh& mesh);

/// Writes `path` atomically (render/AtomicFile.h); returns it. Throws std::system_error naming
/// the file when the write fails.
std::vector<std::filesystem::path> writeGlb(const Mesh& mesh, const std::filesystem::path& path);

}  // namespace rend::render
