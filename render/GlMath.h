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

/// The camera frame that lookAt() builds (right, up, forward), read back from its matrix so a
/// ray tracer frames a scene exactly as the rasterizer does, fallback up vectors included.
struct ViewBasis {
    Eigen::Vector3d right;
    Eigen::Vector3d up;
    Eigen::Vector3d forward;
};
ViewBasis viewBasis(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                    const Eigen::Vector3d& up);

/// World-space direction (not normalised) through normalised device coordinates
/// (ndcX, ndcY) in [-1, 1]^2, +y up, of perspective(fovYDegrees, aspect, ...): the inverse of
/// the projection for a pinhole camera with the frame `basis`.
Eigen::Vector3d cameraRayDirection(const ViewBasis& basis, double fovYDegrees, double aspect,
                                   double ndcX, double ndcY);

}  // namespace rend::render::detail
