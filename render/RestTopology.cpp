#include "render/RestTopology.h"

namespace rend::render {

void incidentTriangles(const std::vector<std::array<int, 3>>& triangles, std::size_t vertexCount,
                       std::vector<int>& offsets, std::vector<int>& incident) {
    offsets.assign(vertexCount + 1, 0);
    for (const auto& t : triangles)
        for (int v : t) ++offsets[v + 1];
    for (std::size_t i = 1; i < offsets.size(); ++i) offsets[i] += offsets[i - 1];
    incident.resize(offsets.back());
    std::vector<int> fill(offsets.begin(), offsets.end() - 1);
    for (int t = 0; t < int(triangles.size()); ++t)
        for (int v : triangles[t]) incident[fill[v]++] = t;
}

}  // namespace rend::render
