#pragma once
// Signed distance from a point to a collider's surface, in the collider's own frame: closed
// forms for the sphere, box and capsule; for a triangle mesh, the closest triangle found through
// a uniform grid, signed by the angle-weighted pseudo-normal of the closest feature (Baerentzen &
// Aanaes, "Signed distance computation using the angle weighted pseudonormal", IEEE TVCG 2005),
// which tells inside from outside of a closed mesh exactly.

#include <Eigen/Core>
#include <array>
#include <optional>
#include <vector>

#include "sim/Collider.h"

namespace rend::sim {

/// The surface point nearest a query: `distance` negative inside, `normal` the outward unit
/// direction along which the query leaves the body.
struct SurfaceDistance {
    double distance = 0.0;
    Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

/// The point of a triangle nearest a query, as barycentric weights of its corners, and the
/// feature holding it: the face, edge k (corner k to k + 1) or corner k.
struct TrianglePoint {
    enum class Feature { Face, Edge, Corner };
    Eigen::Vector3d weights;
    Feature feature = Feature::Face;
    int index = 0;

    Eigen::Vector3d at(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       const Eigen::Vector3d& c) const {
        return weights[0] * a + weights[1] * b + weights[2] * c;
    }
};
TrianglePoint closestOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// A closed triangle mesh prepared for distance queries within `reach` of its surface.
class MeshDistance {
public:
    MeshDistance() = default;
    MeshDistance(const TriangleMesh& mesh, double reach);

    /// Nothing when no triangle lies within reach (far outside, or deep inside: the step limit
    /// keeps particles from getting there).
    std::optional<SurfaceDistance> query(const Eigen::Vector3d& p) const;
    /// The largest distance of a vertex from the mesh's origin.
    double boundingRadius() const { return boundingRadius_; }

private:
    void buildPseudoNormals();
    void buildGrid();
    int cellOf(const Eigen::Vector3d& p) const;  ///< -1 outside the grid

    std::vector<Eigen::Vector3d> vertices_;
    std::vector<std::array<int, 3>> triangles_;
    std::vector<Eigen::Vector3d> faceNormal_, vertexNormal_;
    std::vector<std::array<Eigen::Vector3d, 3>> edgeNormal_;  ///< edge k runs corner k to k+1
    double reach_ = 0.0, boundingRadius_ = 0.0;
    Eigen::Vector3d lo_ = Eigen::Vector3d::Zero();
    double cell_ = 1.0;
    Eigen::Vector3i dims_ = Eigen::Vector3i::Zero();
    std::vector<int> cellStart_, cellTriangles_;  ///< CSR: triangles whose padded box meets a cell
};

/// The signed distance to the collider's surface at `local` (in its frame); nothing for a mesh
/// beyond its reach.
std::optional<SurfaceDistance> signedDistance(const ColliderParams& collider,
                                              const MeshDistance* mesh,
                                              const Eigen::Vector3d& local);

/// The smallest half-thickness of the body: a particle moving less than this in a step cannot
/// cross it unseen.
double halfThickness(const ColliderParams& collider);

/// The largest distance from the collider's origin to its surface.
double boundingRadius(const ColliderParams& collider);

}  // namespace rend::sim
