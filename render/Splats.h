#pragma once
#include <Eigen/Core>
#include <vector>

namespace rend::render {

/// Oriented discs, one per particle: the `splat` surface. Embree traces them directly
/// (RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT); the rasterizer draws them as small polygons.
struct Splats {
    std::vector<Eigen::Vector3f> centers;
    std::vector<Eigen::Vector3f> normals;  ///< unit, from each particle's neighbourhood
    std::vector<Eigen::Vector3f> colors;   ///< linear RGB
    std::vector<Eigen::Vector2f> layers;   ///< the look's layer inputs, as Mesh::layers
    std::vector<float> radii;
};

}  // namespace rend::render
