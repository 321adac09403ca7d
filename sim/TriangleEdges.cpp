#include "sim/TriangleEdges.h"

#include <algorithm>
#include <utility>

namespace rend::sim {

namespace {

std::array<int, 2> sideOf(const std::array<int, 3>& triangle, int side, int firstCorner) {
    const int a = triangle[(side + firstCorner) % 3], b = triangle[(side + firstCorner + 1) % 3];
    return {std::min(a, b), std::max(a, b)};
}

}  // namespace

TriangleEdges triangleEdges(std::span<const std::array<int, 3>> triangles, int firstCorner) {
    int corners = 0;
    for (const auto& t : triangles)
        for (const int v : t) corners = std::max(corners, v + 1);
    // Per lower corner, the edges numbered so far from it: their upper corners and numbers, in
    // room for two sides of each triangle there (a side holds its lower corner).
    std::vector<int> first(std::size_t(corners) + 1, 0);
    for (const auto& t : triangles)
        for (const int v : t) first[v + 1] += 2;
    for (std::size_t v = 1; v < first.size(); ++v) first[v] += first[v - 1];
    std::vector<int> count(corners, 0), upper(first.back()), number(first.back());
    TriangleEdges edges;
    edges.ofTriangle.resize(triangles.size());
    for (int t = 0; t < int(triangles.size()); ++t)
        for (int side = 0; side < 3; ++side) {
            const auto [low, high] = sideOf(triangles[t], side, firstCorner);
            const int* from = upper.data() + first[low];
            const int* end = from + count[low];
            const int* found = std::find(from, end, high);
            int e;
            if (found != end) {
                e = number[found - upper.data()];
            } else {  // the first side with this pair: a new edge
                e = int(edges.ends.size());
                edges.ends.push_back({low, high});
                upper[first[low] + count[low]] = high, number[first[low] + count[low]] = e;
                ++count[low];
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
