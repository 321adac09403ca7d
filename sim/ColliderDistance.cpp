#include "sim/ColliderDistance.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace rend::sim {
namespace {

SurfaceDistance fromCentre(const Eigen::Vector3d& offset, double radius) {
    const double length = offset.norm();
    // At the exact centre any direction is outward; +z is a fixed choice.
    const Eigen::Vector3d normal =
        length > 0.0 ? Eigen::Vector3d(offset / length) : Eigen::Vector3d(Eigen::Vector3d::UnitZ());
    return {length - radius, normal};
}

SurfaceDistance boxDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& half) {
    const Eigen::Vector3d q = p.cwiseAbs() - half;
    const Eigen::Vector3d sign =
        p.cwiseSign().unaryExpr([](double s) { return s < 0 ? -1.0 : 1.0; });
    const Eigen::Vector3d outside = q.cwiseMax(0.0);
    if (outside.squaredNorm() > 0.0) {
        const double d = outside.norm();
        return {d, sign.cwiseProduct(outside) / d};
    }
    int axis = 0;  // inside: out through the nearest face
    q.maxCoeff(&axis);
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    normal[axis] = sign[axis];
    return {q[axis], normal};
}

SurfaceDistance capsuleDistance(const Eigen::Vector3d& p, double radius, double length) {
    const double z = std::clamp(p.z(), -0.5 * length, 0.5 * length);
    return fromCentre(p - Eigen::Vector3d(0, 0, z), radius);
}

}  // namespace

namespace {

double cornerAngle(const Eigen::Vector3d& at, const Eigen::Vector3d& u, const Eigen::Vector3d& w) {
    const Eigen::Vector3d e1 = u - at, e2 = w - at;
    return std::atan2(e1.cross(e2).norm(), e1.dot(e2));
}

}  // namespace

MeshDistance::MeshDistance(const TriangleMesh& mesh, double reach)
    : vertices_(mesh.vertices), triangles_(mesh.triangles), reach_(reach) {
    for (const Eigen::Vector3d& v : vertices_)
        boundingRadius_ = std::max(boundingRadius_, v.norm());
    buildPseudoNormals();
    buildGrid();
}

void MeshDistance::buildPseudoNormals() {
    const int nv = int(vertices_.size());
    vertexNormal_.assign(nv, Eigen::Vector3d::Zero());
    faceNormal_.resize(triangles_.size());
    std::map<std::pair<int, int>, Eigen::Vector3d> edgeSum;
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
        const auto& tri = triangles_[t];
        const Eigen::Vector3d n = (vertices_[tri[1]] - vertices_[tri[0]])
                                      .cross(vertices_[tri[2]] - vertices_[tri[0]])
                                      .normalized();
        faceNormal_[t] = n;
        for (int k = 0; k < 3; ++k) {
            const int a = tri[k], b = tri[(k + 1) % 3], c = tri[(k + 2) % 3];
            vertexNormal_[a] += cornerAngle(vertices_[a], vertices_[b], vertices_[c]) * n;
            // try_emplace zeroes it: Eigen leaves a default-constructed vector uninitialised.
            edgeSum.try_emplace(std::minmax(a, b), Eigen::Vector3d::Zero()).first->second += n;
        }
    }
    for (Eigen::Vector3d& n : vertexNormal_) n.normalize();
    edgeNormal_.resize(triangles_.size());
    for (std::size_t t = 0; t < triangles_.size(); ++t)
        for (int k = 0; k < 3; ++k)
            edgeNormal_[t][k] =
                edgeSum[std::minmax(triangles_[t][k], triangles_[t][(k + 1) % 3])].normalized();
}

// Each triangle is listed in every cell its bounding box, padded by the reach, meets; so the
// one cell holding a query point lists every triangle within reach of it.
void MeshDistance::buildGrid() {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    double edges = 0.0;
    for (const auto& tri : triangles_)
        for (int k = 0; k < 3; ++k) {
            lo = lo.cwiseMin(vertices_[tri[k]]);
            hi = hi.cwiseMax(vertices_[tri[k]]);
            edges += (vertices_[tri[k]] - vertices_[tri[(k + 1) % 3]]).norm();
        }
    lo_ = lo.array() - reach_;
    const Eigen::Vector3d extent = (hi.array() + reach_) - lo_.array();
    const double meanEdge = edges / std::max<std::size_t>(1, 3 * triangles_.size());
    cell_ = std::max({meanEdge, 2.0 * reach_, extent.maxCoeff() / 64.0, 1e-9});
    for (int a = 0; a < 3; ++a) dims_[a] = std::max(1, int(std::ceil(extent[a] / cell_)));
    const auto cellIndex = [&](const Eigen::Vector3i& c) {
        return (c.z() * dims_.y() + c.y()) * dims_.x() + c.x();
    };
    std::vector<std::vector<int>> lists(std::size_t(dims_.prod()));
    for (int t = 0; t < int(triangles_.size()); ++t) {
        Eigen::Vector3d tlo = vertices_[triangles_[t][0]], thi = tlo;
        for (int k = 1; k < 3; ++k) {
            tlo = tlo.cwiseMin(vertices_[triangles_[t][k]]);
            thi = thi.cwiseMax(vertices_[triangles_[t][k]]);
        }
        const Eigen::Vector3i c0 =
            (((tlo.array() - reach_) - lo_.array()) / cell_).floor().cast<int>();
        const Eigen::Vector3i c1 =
            (((thi.array() + reach_) - lo_.array()) / cell_).floor().cast<int>();
        for (int z = std::max(0, c0.z()); z <= std::min(dims_.z() - 1, c1.z()); ++z)
            for (int y = std::max(0, c0.y()); y <= std::min(dims_.y() - 1, c1.y()); ++y)
                for (int x = std::max(0, c0.x()); x <= std::min(dims_.x() - 1, c1.x()); ++x)
                    lists[std::size_t(cellIndex({x, y, z}))].push_back(t);
    }
    cellStart_.assign(lists.size() + 1, 0);
    for (std::size_t c = 0; c < lists.size(); ++c)
        cellStart_[c + 1] = cellStart_[c] + int(lists[c].size());
    cellTriangles_.reserve(std::size_t(cellStart_.back()));
    for (const auto& list : lists)
        cellTriangles_.insert(cellTriangles_.end(), list.begin(), list.end());
}

int MeshDistance::cellOf(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d c = ((p - lo_) / cell_).array().floor();
    for (int a = 0; a < 3; ++a)
        if (!(c[a] >= 0 && c[a] < dims_[a])) return -1;
    return (int(c.z()) * dims_.y() + int(c.y())) * dims_.x() + int(c.x());
}

std::optional<SurfaceDistance> MeshDistance::query(const Eigen::Vector3d& p) const {
    const int cell = cellOf(p);
    if (cell < 0) return std::nullopt;
    double best = reach_ * reach_;
    std::optional<SurfaceDistance> found;
    for (int k = cellStart_[cell]; k < cellStart_[cell + 1]; ++k) {
        const int t = cellTriangles_[k];
        const auto& tri = triangles_[t];
        const TrianglePoint c =
            closestOnTriangle(p, vertices_[tri[0]], vertices_[tri[1]], vertices_[tri[2]]);
        const Eigen::Vector3d point = c.at(vertices_[tri[0]], vertices_[tri[1]], vertices_[tri[2]]);
        const double d2 = (p - point).squaredNorm();
        if (d2 > best || (found && d2 == best)) continue;  // the first of equals, in list order
        best = d2;
        using F = TrianglePoint::Feature;
        const Eigen::Vector3d pseudo = c.feature == F::Face   ? faceNormal_[t]
                                       : c.feature == F::Edge ? edgeNormal_[t][c.index]
                                                              : vertexNormal_[tri[c.index]];
        const Eigen::Vector3d away = p - point;
        const double d = std::sqrt(d2);
        const bool inside = away.dot(pseudo) < 0.0;
        const Eigen::Vector3d normal =
            d > 1e-12 * reach_ ? Eigen::Vector3d((inside ? -away : away) / d) : pseudo;
        found = SurfaceDistance{inside ? -d : d, normal};
    }
    return found;
}

std::optional<SurfaceDistance> signedDistance(const ColliderParams& collider,
                                              const MeshDistance* mesh,
                                              const Eigen::Vector3d& local) {
    switch (collider.shape) {
        case ColliderShape::Sphere:
            return fromCentre(local, collider.radius);
        case ColliderShape::Box:
            return boxDistance(local, 0.5 * collider.size);
        case ColliderShape::Capsule:
            return capsuleDistance(local, collider.radius, collider.length);
        case ColliderShape::Mesh:
            return mesh ? mesh->query(local) : std::nullopt;
    }
    return std::nullopt;
}

double halfThickness(const ColliderParams& collider) {
    switch (collider.shape) {
        case ColliderShape::Sphere:
        case ColliderShape::Capsule:
            return collider.radius;
        case ColliderShape::Box:
            return 0.5 * collider.size.minCoeff();
        case ColliderShape::Mesh:
            break;
    }
    return std::numeric_limits<double>::infinity();  // a mesh's thinnest part is not measured
}

double boundingRadius(const ColliderParams& collider) {
    switch (collider.shape) {
        case ColliderShape::Sphere:
            return collider.radius;
        case ColliderShape::Box:
            return 0.5 * collider.size.norm();
        case ColliderShape::Capsule:
            return collider.radius + 0.5 * collider.length;
        case ColliderShape::Mesh:
            break;
    }
    double r = 0.0;
    if (collider.mesh)
        for (const Eigen::Vector3d& v : collider.mesh->vertices) r = std::max(r, v.norm());
    return r;
}

}  // namespace rend::sim
