#include "sim/TriangleEdges.h"

#include <algorithm>
#include <utility>

namespace rend::sim {

namespace {

std::array<int, 2> sideOf(const std::array<int, 3>& triangle, int side, int firstCorner) {
    const int a = triangle[(side + firstCorner) % 3], b = triangle[(side + firstCorner + 1) % 3];
    return {std::min(a, b), std::max(a, b)};
}

/// trianglesAtCorners over every corner used.
struct CornerTriangles {
    std::vector<int> offsets, at;

    explicit CornerTriangles(std::span<const std::array<int, 3>> triangles) {
        int corners = 0;
        for (const auto& t : triangles)
            for (const int v : t) corners = std::max(corners, v + 1);
        trianglesAtCorners(triangles, std::size_t(corners), offsets, at);
    }
};

}  // namespace

TriangleEdges triangleEdges(std::span<const std::array<int, 3>> triangles, int firstCorner) {
    const CornerTriangles around(triangles);
    TriangleEdges edges;
    edges.ofTriangle.resize(triangles.size());
    // The edge of an earlier side with the same pair: every side using the edge holds its lower
    // corner, so the triangles there hold them all.
    const auto earlier = [&](int t, int side, const std::array<int, 2>& pair) {
        for (int k = around.offsets[pair[0]]; k < around.offsets[pair[0] + 1]; ++k) {
            const int other = around.at[k];
            if (other > t) break;
            const int sides = other == t ? side : 3;
            for (int s = 0; s < sides; ++s)
                if (sideOf(triangles[other], s, firstCorner) == pair)
                    return edges.ofTriangle[other][s];
        }
        return -1;
    };
    for (int t = 0; t < int(triangles.size()); ++t)
        for (int side = 0; side < 3; ++side) {
            const std::array<int, 2> pair = sideOf(triangles[t], side, firstCorner);
            int e = earlier(t, side, pair);
            if (e < 0) {
                e = int(edges.ends.size());
                edges.ends.push_back(pair);
            }
            edges.ofTriangle[t][side] = e;
        }
    return edges;
}

void trianglesAtCorners(std::span<const std::array<int, 3>> triangles, std::size_t cornerCount,
                        std::vector<int>& offsets, std::vector<int>& at) {
    offsets.assign(cornerCount + 1, 0);
    for (const auto& t : triangles)
        for (const int v : t) ++offsets[v + 1];
    for (std::size_t v = 1; v < offsets.size(); ++v) offsets[v] += offsets[v - 1];
    at.resize(offsets.back());
    std::vector<int> next(offsets.begin(), offsets.end() - 1);
    for (int t = 0; t < int(triangles.size()); ++t)
        for (const int v : triangles[t]) at[next[v]++] = t;
}

}  // namespace rend::sim
