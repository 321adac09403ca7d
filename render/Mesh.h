#pragma once
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace rend::render {

/// Triangle mesh handed from a surface to a renderer or exporter.
struct Mesh {
    std::vector<Eigen::Vector3f> positions;
    std::vector<Eigen::Vector3f> normals;  ///< per vertex, unit length
    std::vector<Eigen::Vector3f> colors;   ///< per vertex, linear RGB in [0,1]
    std::vector<std::array<std::uint32_t, 3>> triangles;
};

}  // namespace rend::render
