#include "render/RestTopology.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <utility>

#include "sim/TriangleEdges.h"

namespace rend::render {

namespace {

// A notch is filled when the outline's two edges at it meet at more than this angle, measured
// outside the sheet: the hexagonal zig-zag's notches are 120 degrees, a rectangle's corners 90.
const double kNotchCosine = -0.3;  // cos(107.5 degrees)

}  // namespace

void incidentTriangles(const std::vector<std::array<int, 3>>& triangles, std::size_t vertexCount,
                       std::vector<int>& offsets, std::vector<int>& incident) {
    sim::trianglesAtCorners(triangles, vertexCount, offsets, incident);
}

RestEdges restEdges(const std::vector<std::array<int, 3>>& triangles) {
    sim::TriangleEdges numbered = sim::triangleEdges(triangles, 0);  // side k from corner k
    RestEdges edges;
    edges.ends = std::move(numbered.ends);
    edges.ofTriangle = std::move(numbered.ofTriangle);
    edges.neighbours.assign(triangles.size(), {-1, -1, -1});
    // The first two triangles on each edge.
    edges.triangles.assign(edges.ends.size(), {-1, -1});
    for (int t = 0; t < int(triangles.size()); ++t)
        for (const int e : edges.ofTriangle[t]) {
            auto& on = edges.triangles[e];
            if (on[0] < 0)
                on[0] = t;
            else if (on[1] < 0)
                on[1] = t;
        }
    for (int t = 0; t < int(triangles.size()); ++t)
        for (int k = 0; k < 3; ++k) {
            const int e = edges.ofTriangle[t][k];
            const int other = edges.across(e, t);
            if (edges.triangles[e][0] == t || edges.triangles[e][1] == t)
                edges.neighbours[t][k] = other;
        }
    return edges;
}

std::vector<std::array<int, 2>> outlineNotches(const std::vector<std::array<int, 3>>& triangles,
                                               const RestEdges& edges,
                                               std::span<const Eigen::Vector3d> rest) {
    // Outline edges directed as their one triangle walks them (the sheet on their left), and
    // that triangle's normal, to tell left turns from right ones on a curved rest lattice too.
    const std::size_t n = rest.size();
    std::vector<int> from(n, -1), to(n, -1), fromCount(n, 0), toCount(n, 0);
    std::vector<Eigen::Vector3d> normal(n, Eigen::Vector3d::Zero());
    for (int t = 0; t < int(triangles.size()); ++t) {
        const auto& c = triangles[t];
        const Eigen::Vector3d faceNormal = (rest[c[1]] - rest[c[0]]).cross(rest[c[2]] - rest[c[0]]);
        for (int k = 0; k < 3; ++k) {
            if (edges.neighbours[t][k] >= 0) continue;
            const int a = c[k], b = c[(k + 1) % 3];
            to[a] = b;    // a -> b leaves a
            from[b] = a;  // and enters b
            ++toCount[a];
            ++fromCount[b];
            normal[a] += faceNormal;
            normal[b] += faceNormal;
        }
    }
    std::vector<std::array<int, 2>> notches(n, {-1, -1});
    for (std::size_t v = 0; v < n; ++v) {
        if (fromCount[v] != 1 || toCount[v] != 1) continue;  // inside, or a pinch point
        const Eigen::Vector3d in = rest[v] - rest[from[v]];
        const Eigen::Vector3d out = rest[to[v]] - rest[v];
        const bool rightTurn = in.cross(out).dot(normal[v]) < 0.0;  // concave: a notch
        const double cosine = (-in).normalized().dot(out.normalized());
        if (rightTurn && cosine < kNotchCosine) notches[v] = {from[v], to[v]};
    }
    return notches;
}

}  // namespace rend::render
