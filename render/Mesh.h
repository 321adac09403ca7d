#pragma once
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace rend::render {

/// Triangle mesh handed from a surface to a renderer or exporter.
struct Mesh {
    std::vector<Eigen::Vector3f> positions;
    std::vector<Eigen::Vector3f> normals;  ///< per vertex, unit length
    std::vector<Eigen::Vector3f> colors;   ///< per vertex, linear RGB in [0,1]
    /// Per vertex, the look's layer inputs (theta over color_range, damage), each in [0, 1]
    /// (ColorMap.h particleLayers); empty where a colour map replaces the look.
    std::vector<Eigen::Vector2f> layers;
    std::vector<float> theta;  ///< per vertex, the diffusing quantity; empty when there is none
    std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// Throws std::invalid_argument, naming `who`, when the attribute arrays differ in length or a
/// triangle indexes past the vertices: what every consumer of a Mesh relies on.
inline void checkMesh(const Mesh& mesh, std::string_view who) {
    const std::size_t n = mesh.positions.size();
    const auto fail = [&](const char* what) {
        throw std::invalid_argument(std::string(who) + ": " + what);
    };
    if (mesh.normals.size() != n || (!mesh.colors.empty() && mesh.colors.size() != n) ||
        (!mesh.layers.empty() && mesh.layers.size() != n) ||
        (!mesh.theta.empty() && mesh.theta.size() != n))
        fail("mesh attribute arrays differ in length");
    for (const auto& t : mesh.triangles)
        for (std::uint32_t v : t)
            if (v >= n) fail("triangle index out of range");
}

}  // namespace rend::render
