#include "render/GlMath.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

namespace rend::render::detail {

GlMatrix perspective(double fovYDegrees, double aspect, double zNear, double zFar) {
    const double f = 1.0 / std::tan(fovYDegrees * std::numbers::pi / 360.0);
    GlMatrix m{};
    m[0] = f / aspect;
    m[5] = f;
    m[10] = (zFar + zNear) / (zNear - zFar);
    m[11] = -1.0;
    m[14] = 2.0 * zFar * zNear / (zNear - zFar);
    return m;
}

GlMatrix lookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                const Eigen::Vector3d& up) {
    const Eigen::Vector3d f = (target - eye).normalized();
    Eigen::Vector3d s = f.cross(up);
    // Looking straight along `up` leaves the roll undefined; any perpendicular axis will do.
    if (s.squaredNorm() < 1e-12) s = f.cross(Eigen::Vector3d::UnitY());
    if (s.squaredNorm() < 1e-12) s = f.cross(Eigen::Vector3d::UnitX());
    s.normalize();
    const Eigen::Vector3d u = s.cross(f);
    GlMatrix m{};
    for (int c = 0; c < 3; ++c) {
        m[c * 4 + 0] = s[c];
        m[c * 4 + 1] = u[c];
        m[c * 4 + 2] = -f[c];
    }
    m[12] = -s.dot(eye);
    m[13] = -u.dot(eye);
    m[14] = f.dot(eye);
    m[15] = 1.0;
    return m;
}

ViewBasis viewBasis(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                    const Eigen::Vector3d& up) {
    // The rows of lookAt's rotation are s, u and -f.
    const GlMatrix m = lookAt(eye, target, up);
    return {Eigen::Vector3d(m[0], m[4], m[8]), Eigen::Vector3d(m[1], m[5], m[9]),
            -Eigen::Vector3d(m[2], m[6], m[10])};
}

Eigen::Vector3d cameraRayDirection(const ViewBasis& basis, double fovYDegrees, double aspect,
                                   double ndcX, double ndcY) {
    // perspective() maps a view-space direction (x, y, -1) to ndc (x f / aspect, y f).
    const double tanHalf = std::tan(fovYDegrees * std::numbers::pi / 360.0);
    return basis.forward + basis.right * (ndcX * tanHalf * aspect) + basis.up * (ndcY * tanHalf);
}

}  // namespace rend::render::detail
