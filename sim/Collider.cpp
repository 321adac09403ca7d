#include "sim/Collider.h"

#include <algorithm>
#include <cmath>

namespace rend::sim {
namespace {

/// The angular velocity that turns `from` into `to` in `seconds` at a constant rate (world axis).
Eigen::Vector3d turnRate(const Eigen::Quaterniond& from, const Eigen::Quaterniond& to,
                         double seconds) {
    Eigen::Quaterniond step = to * from.conjugate();
    if (step.w() < 0.0) step.coeffs() = -step.coeffs();  // the short way round, as slerp turns
    const Eigen::AngleAxisd turn(step);
    return turn.axis() * (turn.angle() / seconds);
}

ColliderPose keyframedPose(const std::vector<ColliderKeyframe>& keys, double t) {
    ColliderPose pose;
    if (t <= keys.front().time || keys.size() == 1) {
        pose.position = keys.front().position;
        pose.rotation = keys.front().rotation;
        return pose;
    }
    if (t >= keys.back().time) {
        pose.position = keys.back().position;
        pose.rotation = keys.back().rotation;
        return pose;
    }
    const auto next =
        std::upper_bound(keys.begin(), keys.end(), t,
                         [](double u, const ColliderKeyframe& k) { return u < k.time; });
    const ColliderKeyframe& b = *next;
    const ColliderKeyframe& a = *(next - 1);
    const double span = b.time - a.time;
    const double u = (t - a.time) / span;
    pose.position = a.position + u * (b.position - a.position);
    pose.rotation = a.rotation.slerp(u, b.rotation);
    pose.velocity = (b.position - a.position) / span;
    pose.angularVelocity = turnRate(a.rotation, b.rotation, span);
    return pose;
}

}  // namespace

ColliderPose ColliderParams::poseAt(double t) const {
    if (!keyframes.empty()) return keyframedPose(keyframes, t);
    ColliderPose pose;
    pose.position = position + t * velocity;
    pose.velocity = velocity;
    pose.angularVelocity = spin;
    const double angle = spin.norm() * t;
    pose.rotation = angle > 0.0
                        ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, spin.normalized())) * rotation
                        : rotation;
    return pose;
}

}  // namespace rend::sim
