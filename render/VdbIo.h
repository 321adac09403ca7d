#pragma once
// OpenVDB set-up and file writing shared by render/VdbSurface.cpp and render/SheetVolume.cpp.
// Private to rend_render (it includes OpenVDB); never included from a public header.

#include <openvdb/openvdb.h>

#include <filesystem>

namespace rend::render::vdb {

/// openvdb::initialize, once per process (it registers grid and metadata types for I/O).
void initialize();

/// Writes `grids` to `path` with writeFileAtomic: never half a file under `path`.
/// Throws std::runtime_error naming the path and the reason.
void writeGridsAtomic(const std::filesystem::path& path, const openvdb::GridCPtrVec& grids);

}  // namespace rend::render::vdb
