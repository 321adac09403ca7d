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
/// The closest point of triangle abc to p by Voronoi regions of its corners, edges and face
/// (Ericson, Real-Time Collision Detection, 5.1.5); inline, as the self-contact calls it a few
/// times per particle and step.
inline TrianglePoint closestOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    using F = TrianglePoint::Feature;
    const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0 && d2 <= 0) return {{1, 0, 0}, F::Corner, 0};
    const Eigen::Vector3d bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0 && d4 <= d3) return {{0, 1, 0}, F::Corner, 1};
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        const double u = d1 / (d1 - d3);
        return {{1 - u, u, 0}, F::Edge, 0};
    }
    const Eigen::Vector3d cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0 && d5 <= d6) return {{0, 0, 1}, F::Corner, 2};
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        const double u = d2 / (d2 - d6);
        return {{1 - u, 0, u}, F::Edge, 2};
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
        const double u = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return {{0, 1 - u, u}, F::Edge, 1};
    }
    const double denom = 1.0 / (va + vb + vc);
    const double v = vb * denom, w = vc * denom;
    return {{1 - v - w, v, w}, F::Face, 0};
}

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
