#include "render/ColliderMesh.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

namespace rend::render {

namespace {

using Vec3 = Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;

/// A point of a surface of revolution about local z: its distance from the axis, its height and
/// its outward normal in the (rho, z) half-plane.
struct ProfilePoint {
    double rho, z, normalRho, normalZ;
};

void addVertex(Mesh& mesh, const sim::ColliderPose& pose, const Vec3& local, const Vec3& normal) {
    mesh.positions.push_back(pose.toWorld(local).cast<float>());
    mesh.normals.push_back((pose.rotation * normal).normalized().cast<float>());
}

/// The surface swept by `profile`, which runs from the bottom pole to the top pole (its first
/// and last points lie on the axis and become one vertex each), in `segments` sectors.
Mesh lathe(const std::vector<ProfilePoint>& profile, int segments, const sim::ColliderPose& pose) {
    Mesh mesh;
    const int rings = int(profile.size()) - 2;  // without the poles
    addVertex(mesh, pose, Vec3(0.0, 0.0, profile.front().z), -Vec3::UnitZ());
    for (int i = 1; i <= rings; ++i) {
        const ProfilePoint& p = profile[i];
        for (int j = 0; j < segments; ++j) {
            const double phi = 2.0 * kPi * j / segments;
            const Vec3 radial(std::cos(phi), std::sin(phi), 0.0);
            addVertex(mesh, pose, p.rho * radial + Vec3(0.0, 0.0, p.z),
                      p.normalRho * radial + Vec3(0.0, 0.0, p.normalZ));
        }
    }
    addVertex(mesh, pose, Vec3(0.0, 0.0, profile.back().z), Vec3::UnitZ());
    const auto at = [&](int ring, int j) { return std::uint32_t(1 + (ring - 1) * segments + j); };
    const std::uint32_t top = std::uint32_t(mesh.positions.size() - 1);
    for (int j = 0; j < segments; ++j) {
        const int next = (j + 1) % segments;
        // Angle grows counter-clockwise about +z, so (a, b, c) winds outward on every band.
        mesh.triangles.push_back({0, at(1, next), at(1, j)});
        for (int i = 1; i < rings; ++i) {
            const std::uint32_t a = at(i, j), b = at(i, next), c = at(i + 1, next),
                                d = at(i + 1, j);
            mesh.triangles.push_back({a, b, c});
            mesh.triangles.push_back({a, c, d});
        }
        mesh.triangles.push_back({at(rings, j), at(rings, next), top});
    }
    return mesh;
}

/// A hemisphere's profile from polar angle `from` to `to` (0 at +z), centred at height zc.
void appendArc(std::vector<ProfilePoint>& profile, double radius, double zc, double from, double to,
               int steps) {
    for (int k = 0; k <= steps; ++k) {
        const double theta = from + (to - from) * k / steps;
        const double s = std::sin(theta), c = std::cos(theta);
        profile.push_back({radius * s, zc + radius * c, s, c});
    }
}

Mesh sphere(double radius, const sim::ColliderPose& pose) {
    std::vector<ProfilePoint> profile;
    appendArc(profile, radius, 0.0, kPi, 0.0, kColliderRings);
    return lathe(profile, kColliderSegments, pose);
}

/// The cylinder is the band between the two hemispheres' equators.
Mesh capsule(double radius, double length, const sim::ColliderPose& pose) {
    std::vector<ProfilePoint> profile;
    const int half = kColliderRings / 2;
    appendArc(profile, radius, -0.5 * length, kPi, 0.5 * kPi, half);
    appendArc(profile, radius, 0.5 * length, 0.5 * kPi, 0.0, half);
    return lathe(profile, kColliderSegments, pose);
}

/// Six faces of four vertices each, so that every face keeps its own normal.
Mesh box(const Vec3& size, const sim::ColliderPose& pose) {
    Mesh mesh;
    const Vec3 half = 0.5 * size;
    for (int axis = 0; axis < 3; ++axis) {
        for (const double side : {-1.0, 1.0}) {
            // u x v = the outward normal, so the corners below run counter-clockwise around it.
            Vec3 u = Vec3::Unit((axis + 1) % 3), v = Vec3::Unit((axis + 2) % 3);
            if (side < 0.0) std::swap(u, v);
            const Vec3 normal = side * Vec3::Unit(axis);
            const Vec3 centre = side * half[axis] * Vec3::Unit(axis);
            const std::uint32_t first = std::uint32_t(mesh.positions.size());
            for (const auto& [cu, cv] :
                 {std::pair{-1.0, -1.0}, {1.0, -1.0}, {1.0, 1.0}, {-1.0, 1.0}})
                addVertex(mesh, pose,
                          centre + cu * half.cwiseProduct(u) + cv * half.cwiseProduct(v), normal);
            mesh.triangles.push_back({first, first + 1, first + 2});
            mesh.triangles.push_back({first, first + 2, first + 3});
        }
    }
    return mesh;
}

/// Angle-weighted vertex normals (Thürmer & Wüthrich 1998, "Computing Vertex Normals from
/// Polygonal Meshes"): unlike area weights, they do not change when a face is split further.
std::vector<Vec3> angleWeightedNormals(const std::vector<Vec3>& x, const Mesh& mesh) {
    std::vector<Vec3> sum(x.size(), Vec3::Zero());
    for (const auto& t : mesh.triangles) {
        const Vec3 n = (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]);
        if (n.squaredNorm() == 0.0) continue;  // a degenerate face has no direction to add
        for (int k = 0; k < 3; ++k) {
            const Vec3 e1 = x[t[(k + 1) % 3]] - x[t[k]], e2 = x[t[(k + 2) % 3]] - x[t[k]];
            const double angle = std::atan2(e1.cross(e2).norm(), e1.dot(e2));
            sum[t[k]] += angle * n.normalized();
        }
    }
    for (Vec3& n : sum) n = n.squaredNorm() > 0.0 ? Vec3(n.normalized()) : Vec3(Vec3::UnitZ());
    return sum;
}

Mesh triangleMesh(const sim::TriangleMesh* source, const sim::ColliderPose& pose) {
    if (!source) throw std::invalid_argument("colliderMesh: a mesh collider without a mesh");
    Mesh mesh;
    std::vector<Vec3> world;
    world.reserve(source->vertices.size());
    for (const Vec3& v : source->vertices) world.push_back(pose.toWorld(v));
    const int n = int(world.size());
    for (const auto& t : source->triangles) {
        for (int v : t)
            if (v < 0 || v >= n)
                throw std::invalid_argument("colliderMesh: triangle index " + std::to_string(v) +
                                            " outside the mesh's " + std::to_string(n) +
                                            " vertices");
        mesh.triangles.push_back({std::uint32_t(t[0]), std::uint32_t(t[1]), std::uint32_t(t[2])});
    }
    for (const Vec3& n : angleWeightedNormals(world, mesh)) mesh.normals.push_back(n.cast<float>());
    for (const Vec3& p : world) mesh.positions.push_back(p.cast<float>());
    return mesh;
}

}  // namespace

Mesh colliderMesh(const sim::ColliderParams& collider, const sim::ColliderPose& pose) {
    switch (collider.shape) {
        case sim::ColliderShape::Sphere:
            return sphere(collider.radius, pose);
        case sim::ColliderShape::Box:
            return box(collider.size, pose);
        case sim::ColliderShape::Capsule:
            return capsule(collider.radius, collider.length, pose);
        case sim::ColliderShape::Mesh:
            return triangleMesh(collider.mesh.get(), pose);
    }
    throw std::invalid_argument("colliderMesh: unknown collider shape");
}

std::vector<Mesh> colliderMeshes(const sim::FrameView& frame) {
    if (frame.colliders.size() != frame.colliderPoses.size())
        throw std::invalid_argument("colliderMeshes: the frame has " +
                                    std::to_string(frame.colliders.size()) + " colliders but " +
                                    std::to_string(frame.colliderPoses.size()) + " poses");
    std::vector<Mesh> meshes;
    meshes.reserve(frame.colliders.size());
    for (std::size_t i = 0; i < frame.colliders.size(); ++i)
        meshes.push_back(colliderMesh(frame.colliders[i], frame.colliderPoses[i]));
    return meshes;
}

}  // namespace rend::render
