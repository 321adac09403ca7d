#pragma once
// Contact parameters and the kinematic colliders of a scene (issue 13): a ground plane, spheres,
// boxes, capsules and triangle meshes, static or moving, with Coulomb friction; and the sheet's
// self-contact. The shapes are plain data: sim/Contact.h resolves contact against them, and the
// renderers draw them from the poses the FrameView carries.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <vector>

namespace rend::sim {

/// Coulomb friction: a contact sticks while the tangential impulse it needs is at most
/// `stiction` times the normal one, and slides with `kinetic` times the normal one otherwise.
struct Friction {
    double kinetic = 0.5;
    double stiction = 0.5;  ///< the static coefficient (>= kinetic in any real pair)
};

/// Shapes in the collider's own frame: a sphere of `radius` about the origin; a box of full
/// extents `size` centred on it; a capsule, the points within `radius` of the segment from
/// (0, 0, -length/2) to (0, 0, length/2); or a closed triangle mesh (outward-facing).
enum class ColliderShape { Sphere, Box, Capsule, Mesh };

struct TriangleMesh {
    std::vector<Eigen::Vector3d> vertices;
    std::vector<std::array<int, 3>> triangles;  ///< counter-clockwise seen from outside
};

/// A pose at one time: world = position + rotation * local.
struct ColliderPose {
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();         ///< of the origin [m/s]
    Eigen::Vector3d angularVelocity = Eigen::Vector3d::Zero();  ///< world axis [rad/s]

    Eigen::Vector3d toLocal(const Eigen::Vector3d& world) const {
        return rotation.conjugate() * (world - position);
    }
    Eigen::Vector3d toWorld(const Eigen::Vector3d& local) const {
        return position + rotation * local;
    }
    /// The velocity of the rigid body's point at `world`.
    Eigen::Vector3d velocityAt(const Eigen::Vector3d& world) const {
        return velocity + angularVelocity.cross(world - position);
    }
};

/// A keyframe of a moving collider; between keys the position is interpolated linearly and the
/// rotation by slerp, before the first and after the last the collider holds still.
struct ColliderKeyframe {
    double time = 0.0;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
};

struct ColliderParams {
    ColliderShape shape = ColliderShape::Sphere;
    double radius = 0.5;                       ///< sphere, capsule [m]
    Eigen::Vector3d size{1.0, 1.0, 1.0};       ///< box: full extents [m]
    double length = 1.0;                       ///< capsule: the segment's length [m]
    std::shared_ptr<const TriangleMesh> mesh;  ///< Mesh: in the collider's frame
    /// The pose at t = 0. Without keyframes the collider moves at a constant `velocity` and
    /// turns at a constant `spin` (world axis, rad/s) about its origin.
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    Eigen::Vector3d spin = Eigen::Vector3d::Zero();
    std::vector<ColliderKeyframe> keyframes;  ///< by time; when given, they set the pose
    Friction friction;

    /// Where the collider is, and how fast it moves, at time t.
    ColliderPose poseAt(double t) const;
};

/// The ground plane z = height, which nothing passes below.
struct GroundParams {
    bool enabled = false;
    double height = 0.0;
    Friction friction;
};

/// Particles of the sheet that are not bonded neighbours at rest repel within `thickness`.
struct SelfContactParams {
    bool enabled = false;
    double thickness = 0.0;  ///< 0: half the spacing, never below the sheet's thickness
    Friction friction{0.3, 0.3};
};

struct ContactParams {
    GroundParams ground;
    std::vector<ColliderParams> colliders;
    SelfContactParams self;

    bool any() const { return ground.enabled || !colliders.empty() || self.enabled; }
};

}  // namespace rend::sim
