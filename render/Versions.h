#pragma once
#include <string>
#include <utility>
#include <vector>

namespace rend::render {

/// (library, version actually in use) for every rendering library linked: Embree (from a
/// created device), OpenVDB, assimp, OSMesa (GL renderer string), stb.
std::vector<std::pair<std::string, std::string>> renderLibraryVersions();

}  // namespace rend::render
