#include "render/LatticeSurface.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <limits>
#include <unordered_map>

#include "render/ColorMap.h"
#include "render/RestTopology.h"

namespace rend::render {

namespace {

constexpr std::uint32_t kUnassigned = std::numeric_limits<std::uint32_t>::max();

std::vector<Eigen::Vector3f> smoothNormals(const std::vector<Eigen::Vector3f>& positions,
                                           const std::vector<std::array<std::uint32_t, 3>>& tris) {
    std::vector<Eigen::Vector3f> normals(positions.size(), Eigen::Vector3f::Zero());
    for (const auto& t : tris) {
        // The unnormalised cross product is twice the area, which gives area weighting.
        const Eigen::Vector3f n =
            (positions[t[1]] - positions[t[0]]).cross(positions[t[2]] - positions[t[0]]);
        for (std::uint32_t v : t) normals[v] += n;
    }
    for (auto& n : normals) {
        const float len = n.norm();
        n = len > 0.0f ? Eigen::Vector3f(n / len) : Eigen::Vector3f::UnitZ();
    }
    return normals;
}

// Pairs every interior edge with the triangle on its other side. The rest lattice is a planar
// triangulation, so an edge has at most two triangles; a third (never produced by sim/) is
// left unpaired rather than guessed at.
std::vector<std::array<int, 3>> edgeNeighbours(const std::vector<std::array<int, 3>>& tris) {
    std::vector<std::array<int, 3>> neighbours(tris.size(), {-1, -1, -1});
    std::unordered_map<std::uint64_t, std::array<int, 2>> firstSide;  // (triangle, edge)
    firstSide.reserve(tris.size() * 2);
    for (int t = 0; t < static_cast<int>(tris.size()); ++t) {
        for (int e = 0; e < 3; ++e) {
            const auto [a, b] = std::minmax(tris[t][e], tris[t][(e + 1) % 3]);
            const std::uint64_t key = (std::uint64_t(std::uint32_t(a)) << 32) | std::uint32_t(b);
            const auto [it, inserted] = firstSide.try_emplace(key, std::array<int, 2>{t, e});
            if (inserted || neighbours[it->second[0]][it->second[1]] >= 0) continue;
            neighbours[it->second[0]][it->second[1]] = t;
            neighbours[t][e] = it->second[0];
        }
    }
    return neighbours;
}

int vertexCount(const sim::FrameView& rest, const std::vector<std::array<int, 3>>& tris) {
    int n = static_cast<int>(rest.particleCount());
    for (const auto& t : tris) n = std::max(n, 1 + std::max({t[0], t[1], t[2]}));
    return n;
}

// Edges used by exactly one triangle, directed as that triangle walks them. With the fans
// split at cracks these are the sheet's outline and both lips of every crack.
std::vector<std::array<std::uint32_t, 2>> boundaryEdges(
    const std::vector<std::array<std::uint32_t, 3>>& tris) {
    struct Directed {
        std::uint64_t key;  // undirected: (min, max)
        std::uint32_t from, to;
    };
    std::vector<Directed> edges;
    edges.reserve(tris.size() * 3);
    for (const auto& t : tris) {
        for (int e = 0; e < 3; ++e) {
            const std::uint32_t a = t[e];
            const std::uint32_t b = t[(e + 1) % 3];
            const auto [lo, hi] = std::minmax(a, b);
            edges.push_back({(std::uint64_t(lo) << 32) | hi, a, b});
        }
    }
    std::sort(edges.begin(), edges.end(),
              [](const Directed& x, const Directed& y) { return x.key < y.key; });
    std::vector<std::array<std::uint32_t, 2>> boundary;
    for (std::size_t i = 0; i < edges.size();) {
        std::size_t j = i + 1;
        while (j < edges.size() && edges[j].key == edges[i].key) ++j;
        if (j - i == 1) boundary.push_back({edges[i].from, edges[i].to});
        i = j;
    }
    return boundary;
}

// Outward wall normals, one per boundary vertex: the sum over its boundary edges of
// (b - a) x n, which points away from the kept triangle on a counter-clockwise edge a -> b.
std::vector<Eigen::Vector3f> wallNormals(const Mesh& sheet,
                                         const std::vector<std::array<std::uint32_t, 2>>& edges) {
    std::vector<Eigen::Vector3f> normals(sheet.positions.size(), Eigen::Vector3f::Zero());
    for (const auto& [a, b] : edges) {
        const Eigen::Vector3f n = sheet.normals[a] + sheet.normals[b];
        const Eigen::Vector3f out = (sheet.positions[b] - sheet.positions[a]).cross(n);
        normals[a] += out;
        normals[b] += out;
    }
    for (auto& n : normals) n.normalize();
    return normals;
}

// Wall vertices get their own copies (with the wall's normal), so the rim is shaded as a wall
// rather than smeared between the two faces; their positions are exact copies of the face
// vertices, so the solid is closed once coincident vertices are welded.
void addWalls(Mesh& mesh, std::uint32_t sheetVertices,
              const std::vector<std::array<std::uint32_t, 2>>& edges,
              const std::vector<Eigen::Vector3f>& normals) {
    std::vector<std::uint32_t> wall(sheetVertices, kUnassigned);  // top copy; bottom is + 1
    auto wallVertex = [&](std::uint32_t v) {
        if (wall[v] != kUnassigned) return wall[v];
        wall[v] = static_cast<std::uint32_t>(mesh.positions.size());
        for (std::uint32_t face : {v, v + sheetVertices}) {
            mesh.positions.push_back(mesh.positions[face]);
            mesh.normals.push_back(normals[v]);
            mesh.colors.push_back(mesh.colors[v]);
            if (!mesh.theta.empty()) mesh.theta.push_back(mesh.theta[v]);
        }
        return wall[v];
    };
    for (const auto& [a, b] : edges) {
        const std::uint32_t ta = wallVertex(a);
        const std::uint32_t tb = wallVertex(b);
        mesh.triangles.push_back({ta, ta + 1, tb + 1});
        mesh.triangles.push_back({ta, tb + 1, tb});
    }
}

// The sheet offset by +-thickness/2 along its vertex normals (the bottom copy wound the other
// way so it faces out) and closed by walls along every boundary edge.
void extrude(Mesh& mesh, double thickness) {
    const auto n = static_cast<std::uint32_t>(mesh.positions.size());
    const auto edges = boundaryEdges(mesh.triangles);
    const auto walls = wallNormals(mesh, edges);
    const float half = static_cast<float>(0.5 * thickness);
    mesh.positions.reserve(2 * n + 2 * edges.size());
    for (std::uint32_t v = 0; v < n; ++v) {
        mesh.positions.push_back(mesh.positions[v] - half * mesh.normals[v]);
        mesh.positions[v] += half * mesh.normals[v];
        mesh.normals.push_back(-mesh.normals[v]);
        mesh.colors.push_back(mesh.colors[v]);
        if (!mesh.theta.empty()) mesh.theta.push_back(mesh.theta[v]);
    }
    const std::size_t faces = mesh.triangles.size();
    for (std::size_t t = 0; t < faces; ++t) {
        const auto tri = mesh.triangles[t];
        mesh.triangles.push_back({tri[0] + n, tri[2] + n, tri[1] + n});
    }
    addWalls(mesh, n, edges, walls);
}

}  // namespace

LatticeSurface::LatticeSurface(const sim::FrameView& rest)
    : triangles_(rest.restTriangles.begin(), rest.restTriangles.end()),
      edgeNeighbours_(edgeNeighbours(triangles_)) {
    // Ascending triangle order fixes which fan keeps the particle's own vertex.
    incidentTriangles(triangles_, vertexCount(rest, triangles_), incidentOffsets_, incident_);
}

std::vector<std::uint8_t> LatticeSurface::keptFlags(const sim::FrameView& frame) const {
    std::vector<std::uint8_t> kept(triangles_.size(), 0);
    for (std::size_t t = 0; t < triangles_.size(); ++t) kept[t] = frame.triangleKept(t) ? 1 : 0;
    return kept;
}

std::vector<int> LatticeSurface::keptTriangles(const sim::FrameView& frame) const {
    const std::vector<std::uint8_t> flags = keptFlags(frame);
    std::vector<int> kept;
    kept.reserve(triangles_.size());
    for (std::size_t t = 0; t < flags.size(); ++t)
        if (flags[t]) kept.push_back(static_cast<int>(t));
    return kept;
}

int LatticeSurface::cornerOf(int triangle, int particle) const {
    const auto& t = triangles_[triangle];
    return t[0] == particle ? 0 : (t[1] == particle ? 1 : 2);
}

// Gives `vertex` to particle's corner in every kept triangle reachable from `start` across
// kept edges through the particle (two triangles both holding the particle and sharing an
// edge share one through it, so only the two edges at its corner need following).
void LatticeSurface::walkFan(int start, int particle, std::uint32_t vertex,
                             const std::vector<std::uint8_t>& kept, Corners& corners,
                             std::vector<int>& stack) const {
    stack.assign(1, start);
    corners.vertex[start][cornerOf(start, particle)] = vertex;
    while (!stack.empty()) {
        const int t = stack.back();
        stack.pop_back();
        const int c = cornerOf(t, particle);
        for (int e : {c, (c + 2) % 3}) {
            const int n = edgeNeighbours_[t][e];
            if (n < 0 || !kept[n]) continue;
            std::uint32_t& slot = corners.vertex[n][cornerOf(n, particle)];
            if (slot != kUnassigned) continue;
            slot = vertex;
            stack.push_back(n);
        }
    }
}

LatticeSurface::Corners LatticeSurface::splitFans(const std::vector<std::uint8_t>& kept,
                                                  std::size_t particleCount) const {
    Corners corners;
    corners.vertex.assign(triangles_.size(), {kUnassigned, kUnassigned, kUnassigned});
    std::vector<int> stack;
    for (int p = 0; p + 1 < static_cast<int>(incidentOffsets_.size()); ++p) {
        bool first = true;
        for (int k = incidentOffsets_[p]; k < incidentOffsets_[p + 1]; ++k) {
            const int t = incident_[k];
            if (!kept[t] || corners.vertex[t][cornerOf(t, p)] != kUnassigned) continue;
            std::uint32_t vertex = static_cast<std::uint32_t>(p);
            if (!first) {
                vertex = static_cast<std::uint32_t>(particleCount + corners.copyOf.size());
                corners.copyOf.push_back(p);
            }
            first = false;
            walkFan(t, p, vertex, kept, corners, stack);
        }
    }
    return corners;
}

Mesh LatticeSurface::build(const sim::FrameView& frame, const RenderSettings& settings) const {
    const std::vector<std::uint8_t> kept = keptFlags(frame);
    const std::size_t n = frame.particleCount();
    const Corners corners = splitFans(kept, n);
    Mesh mesh;
    // Every particle stays a vertex so indices match the frame; unreferenced ones are harmless.
    mesh.positions.reserve(n + corners.copyOf.size());
    for (const auto& p : frame.positions) mesh.positions.push_back(p.cast<float>());
    for (int p : corners.copyOf) mesh.positions.push_back(mesh.positions[p]);
    for (std::size_t t = 0; t < triangles_.size(); ++t)
        if (kept[t]) mesh.triangles.push_back(corners.vertex[t]);
    mesh.normals = smoothNormals(mesh.positions, mesh.triangles);
    mesh.colors = particleColors(frame, settings);
    mesh.colors.reserve(mesh.positions.size());
    for (int p : corners.copyOf) mesh.colors.push_back(mesh.colors[p]);
    if (!frame.theta.empty()) {  // for the EXR's theta layer
        mesh.theta.assign(frame.theta.begin(), frame.theta.end());
        for (int p : corners.copyOf) mesh.theta.push_back(mesh.theta[p]);
    }
    if (settings.thickness > 0.0) extrude(mesh, settings.thickness);
    return mesh;
}

}  // namespace rend::render
