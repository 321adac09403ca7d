#pragma once
// Column-major 4x4 matrices for glLoadMatrixd, built by hand because GLU is not a dependency.

#include <Eigen/Core>
#include <array>

namespace rend::render::detail {

using GlMatrix = std::array<double, 16>;

/// gluPerspective's matrix; fovY in degrees.
GlMatrix perspective(double fovYDegrees, double aspect, double zNear, double zFar);

/// gluLookAt's matrix; falls back to another up vector when `up` is parallel to the view.
GlMatrix lookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                const Eigen::Vector3d& up);

}  // namespace rend::render::detail
