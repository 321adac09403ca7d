#pragma once
// What a renderer needs to know besides the frame: camera, lights, colouring, image size.

#include <Eigen/Core>
#include <array>
#include <optional>

namespace rend::render {

/// Theta: the diffusive quantity, light red -> dark red as in the membrane paper's figures.
/// Damage: per-particle damage in [0, 1].
enum class ColorBy { None, Speed, Strain, Theta, Damage };

struct Camera {
    Eigen::Vector3d position{0.0, -4.0, 3.0};
    Eigen::Vector3d lookAt{0.0, 0.0, 0.0};
    Eigen::Vector3d up{0.0, 0.0, 1.0};
    double fovYDegrees = 40.0;
};

struct DirectionalLight {
    Eigen::Vector3d direction{-0.4, -0.5, 1.0};  ///< points from the surface towards the light
    Eigen::Vector3d color{1.0, 1.0, 1.0};
    double intensity = 0.85;
};

struct RenderSettings {
    int width = 960;
    int height = 540;
    int supersample = 2;  ///< render at N x N the size and box-filter down
    Camera camera;
    DirectionalLight sun;
    double ambient = 0.25;
    Eigen::Vector3d background{0.80, 0.84, 0.90};
    bool ground = true;
    double groundHeight = -0.5;  ///< z of the ground plane
    Eigen::Vector3d groundColor{0.55, 0.55, 0.52};
    Eigen::Vector3d albedo{0.78, 0.80, 0.85};  ///< material colour when ColorBy::None
    ColorBy colorBy = ColorBy::None;
    std::optional<std::array<double, 2>> colorRange;  ///< nullopt: 0..max of the frame
};

}  // namespace rend::render
