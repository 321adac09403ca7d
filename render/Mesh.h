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
    /// Per vertex, what the simulation knows of it, for exports: the particle it belongs to (a
    /// crack lip's or bow-tie copy's own particle; a triangle's centroid, its first corner), its
    /// velocity, damage, and rest position (where textures stay put). Empty where a surface
    /// does not follow particles (splat discs, the VDB level set).
    struct Point {
        std::int32_t id = -1;
        Eigen::Vector3f velocity = Eigen::Vector3f::Zero();
        float damage = 0.0f;
        Eigen::Vector3f rest = Eigen::Vector3f::Zero();
    };
    std::vector<Point> points;
    std::vector<std::array<std::uint32_t, 3>> triangles;

    /// Empties every array, keeping its storage.
    void clear() {
        positions.clear(), normals.clear(), colors.clear(), layers.clear(), theta.clear();
        points.clear(), triangles.clear();
    }
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
        (!mesh.theta.empty() && mesh.theta.size() != n) ||
        (!mesh.points.empty() && mesh.points.size() != n))
        fail("mesh attribute arrays differ in length");
    for (const auto& t : mesh.triangles)
        for (std::uint32_t v : t)
            if (v >= n) fail("triangle index out of range");
}

}  // namespace rend::render
