#include "render/LatticeSurface.h"

#include <Eigen/Geometry>
#include <cstdint>

#include "render/ColorMap.h"

namespace rend::render {

namespace {

bool bondIntact(const sim::FrameView& frame, int bond) {
    // Edges without a bond (e.g. square-lattice diagonals) carry no damage information, so
    // they never drop their triangle.
    return bond < 0 || frame.bondAlive[bond] != 0;
}

std::array<int, 3> edgeBonds(const sim::FrameView& rest, const std::array<int, 3>& t) {
    std::array<int, 3> bonds{};
    for (int e = 0; e < 3; ++e) bonds[e] = rest.findBond(t[e], t[(e + 1) % 3]);
    return bonds;
}

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

}  // namespace

LatticeSurface::LatticeSurface(const sim::FrameView& rest)
    : triangles_(rest.restTriangles.begin(), rest.restTriangles.end()) {
    edgeBonds_.reserve(triangles_.size());
    for (const auto& t : triangles_) edgeBonds_.push_back(edgeBonds(rest, t));
}

std::vector<int> LatticeSurface::keptTriangles(const sim::FrameView& frame) const {
    std::vector<int> kept;
    kept.reserve(triangles_.size());
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
        bool intact = true;
        for (int e = 0; e < 3; ++e) intact = intact && bondIntact(frame, edgeBonds_[t][e]);
        if (intact) kept.push_back(static_cast<int>(t));
    }
    return kept;
}

Mesh LatticeSurface::build(const sim::FrameView& frame, const RenderSettings& settings) const {
    Mesh mesh;
    // Every particle stays a vertex so indices match the frame; unreferenced ones are harmless.
    mesh.positions.reserve(frame.particleCount());
    for (const auto& p : frame.positions) mesh.positions.push_back(p.cast<float>());
    for (int t : keptTriangles(frame)) {
        const auto& tri = triangles_[t];
        mesh.triangles.push_back({static_cast<std::uint32_t>(tri[0]),
                                  static_cast<std::uint32_t>(tri[1]),
                                  static_cast<std::uint32_t>(tri[2])});
    }
    mesh.normals = smoothNormals(mesh.positions, mesh.triangles);
    mesh.colors = particleColors(frame, settings);
    return mesh;
}

}  // namespace rend::render
