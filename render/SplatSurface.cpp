#include "render/SplatSurface.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "render/ColorMap.h"
#include "render/RestTopology.h"
#include "sim/Parallel.h"

namespace rend::render {

namespace {

// Discs of 0.6 dx overlap their neighbours on the hexagonal lattice (which needs dx / sqrt(3)
// = 0.577 dx to cover the plane). A lattice whose triangles have a larger circumradius (the
// square lattice's right triangles need dx / sqrt(2)) gets that radius plus a margin instead:
// every point of an acute or right triangle lies within its circumradius of a corner.
constexpr double kSpacingFactor = 0.6;
constexpr double kCircumradiusMargin = 1.05;

// Below this ratio of the middle to the largest covariance eigenvalue the neighbours lie on a
// line, and the smallest eigenvector is an arbitrary direction around it.
constexpr double kCollinearRatio = 1e-4;

// Shortest rest edge per particle over the rest triangles (+inf where it has none): the
// spacing of particles that have no bonds.
std::vector<double> triangleEdgeMinima(const sim::FrameView& rest) {
    std::vector<double> shortest(rest.particleCount(), std::numeric_limits<double>::infinity());
    for (const auto& t : rest.restTriangles) {
        for (int e = 0; e < 3; ++e) {
            const int a = t[e];
            const int b = t[(e + 1) % 3];
            const double len = (rest.restPositions[a] - rest.restPositions[b]).norm();
            shortest[a] = std::min(shortest[a], len);
            shortest[b] = std::min(shortest[b], len);
        }
    }
    return shortest;
}

double shortestBond(const sim::FrameView& rest, int particle) {
    double shortest = std::numeric_limits<double>::infinity();
    for (int b = rest.bondOffsets[particle]; b < rest.bondOffsets[particle + 1]; ++b)
        shortest = std::min(shortest, rest.bondRestLength[b]);
    return shortest;
}

double circumradius(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    const double ab = (b - a).norm();
    const double bc = (c - b).norm();
    const double ca = (a - c).norm();
    const double twiceArea = (b - a).cross(c - a).norm();
    return twiceArea > 0.0 ? ab * bc * ca / (2.0 * twiceArea) : 0.0;
}

double meanCircumradius(const sim::FrameView& rest) {
    if (rest.restTriangles.empty()) return 0.0;
    double sum = 0.0;
    for (const auto& t : rest.restTriangles)
        sum += circumradius(rest.restPositions[t[0]], rest.restPositions[t[1]],
                            rest.restPositions[t[2]]);
    return sum / double(rest.restTriangles.size());
}

// Any unit vector perpendicular to `axis` (unit), preferring the part of `reference` that is.
Eigen::Vector3d perpendicularTowards(const Eigen::Vector3d& axis,
                                     const Eigen::Vector3d& reference) {
    Eigen::Vector3d n = reference - reference.dot(axis) * axis;
    if (n.norm() < 1e-9) n = axis.unitOrthogonal();
    return n.normalized();
}

// Nearest intact-bond neighbour whose normal came from triangles, or +z: which side of a PCA
// plane is "up" for this particle.
Eigen::Vector3d referenceDirection(const sim::FrameView& frame,
                                   const std::vector<Eigen::Vector3f>& normals,
                                   const std::vector<std::uint8_t>& fromTriangles, int particle) {
    Eigen::Vector3d reference = Eigen::Vector3d::UnitZ();
    double nearest = std::numeric_limits<double>::infinity();
    for (int b = frame.bondOffsets[particle]; b < frame.bondOffsets[particle + 1]; ++b) {
        const int j = frame.bondPartners[b];
        if (!frame.bondAlive[b] || !fromTriangles[j]) continue;
        const double d = (frame.positions[j] - frame.positions[particle]).squaredNorm();
        if (d < nearest) {
            nearest = d;
            reference = normals[j].cast<double>();
        }
    }
    return reference;
}

// Tangent basis (u, v) with u x v = n, for laying out a disc's rim counter-clockwise about n.
std::pair<Eigen::Vector3f, Eigen::Vector3f> discBasis(const Eigen::Vector3f& n) {
    const Eigen::Vector3f u = n.unitOrthogonal();
    return {u, n.cross(u)};
}

}  // namespace

double restSpacing(const sim::FrameView& rest) {
    const std::vector<double> fromTriangles = triangleEdgeMinima(rest);
    const bool hasBonds = rest.bondOffsets.size() == rest.particleCount() + 1;
    double sum = 0.0;
    int counted = 0;
    for (int i = 0; i < int(rest.particleCount()); ++i) {
        double d = hasBonds ? shortestBond(rest, i) : std::numeric_limits<double>::infinity();
        if (!std::isfinite(d) || d <= 0.0) d = fromTriangles[i];
        if (!std::isfinite(d) || d <= 0.0) continue;
        sum += d;
        ++counted;
    }
    return counted > 0 ? sum / counted : 0.0;
}

SplatSurface::SplatSurface(const sim::FrameView& rest)
    : triangles_(rest.restTriangles.begin(), rest.restTriangles.end()) {
    const double dx = restSpacing(rest);
    if (dx <= 0.0)
        throw std::invalid_argument(
            "splat surface: the rest lattice has no bond and no triangle to size discs from");
    radius_ = std::max(kSpacingFactor * dx, kCircumradiusMargin * meanCircumradius(rest));
    incidentTriangles(triangles_, rest.particleCount(), incidentOffsets_, incident_);
}

std::vector<std::uint8_t> SplatSurface::keptTriangles(const sim::FrameView& frame) const {
    std::vector<std::uint8_t> kept(triangles_.size(), 0);
    for (std::size_t t = 0; t < triangles_.size(); ++t) kept[t] = frame.triangleKept(t) ? 1 : 0;
    return kept;
}

Eigen::Vector3d SplatSurface::triangleNormal(const sim::FrameView& frame,
                                             const std::vector<std::uint8_t>& kept,
                                             int particle) const {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int k = incidentOffsets_[particle]; k < incidentOffsets_[particle + 1]; ++k) {
        const int t = incident_[k];
        if (!kept[t]) continue;
        const auto& c = triangles_[t];
        const Eigen::Vector3d& x0 = frame.positions[c[0]];
        // The winding is counter-clockwise from +z at rest, so no flip is ever needed: the
        // cross product stays on the rest lattice's +z side through any fold.
        sum += (frame.positions[c[1]] - x0).cross(frame.positions[c[2]] - x0);
    }
    return sum;
}

Eigen::Vector3f SplatSurface::fallbackNormal(const sim::FrameView& frame,
                                             const std::vector<Eigen::Vector3f>& normals,
                                             const std::vector<std::uint8_t>& fromTriangles,
                                             int particle) const {
    std::vector<Eigen::Vector3d> points{frame.positions[particle]};
    for (int b = frame.bondOffsets[particle]; b < frame.bondOffsets[particle + 1]; ++b)
        if (frame.bondAlive[b]) points.push_back(frame.positions[frame.bondPartners[b]]);
    if (points.size() < 2) return Eigen::Vector3f::UnitZ();  // isolated
    const Eigen::Vector3d reference = referenceDirection(frame, normals, fromTriangles, particle);
    if (points.size() == 2)  // one bond: any direction across it; take the one nearest "up"
        return perpendicularTowards((points[1] - points[0]).normalized(), reference).cast<float>();
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& p : points) mean += p;
    mean /= double(points.size());
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (const auto& p : points) covariance += (p - mean) * (p - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
    const Eigen::Vector3d values = eigen.eigenvalues();  // ascending
    if (values[1] <= kCollinearRatio * values[2])
        return perpendicularTowards(eigen.eigenvectors().col(2), reference).cast<float>();
    Eigen::Vector3d n = eigen.eigenvectors().col(0);
    if (n.dot(reference) < 0.0) n = -n;
    return n.normalized().cast<float>();
}

Splats SplatSurface::build(const sim::FrameView& frame, const RenderSettings& settings) const {
    const int n = int(frame.particleCount());
    const std::vector<std::uint8_t> kept = keptTriangles(frame);
    Splats splats;
    splats.centers.resize(n);
    splats.normals.resize(n);
    splats.radii.assign(n, float(radius_));
    std::vector<std::uint8_t> fromTriangles(n, 0);
    // Triangle normals first: the fallback below orients itself by its neighbours' ones.
#pragma omp parallel for schedule(static) if (n > sim::kParallelThreshold)
    for (int i = 0; i < n; ++i) {
        splats.centers[i] = frame.positions[i].cast<float>();
        const Eigen::Vector3d sum = triangleNormal(frame, kept, i);
        const double len = sum.norm();
        fromTriangles[i] = len > 0.0;
        splats.normals[i] =
            len > 0.0 ? Eigen::Vector3f((sum / len).cast<float>()) : Eigen::Vector3f::UnitZ();
    }
    for (int i = 0; i < n; ++i)
        if (!fromTriangles[i])
            splats.normals[i] = fallbackNormal(frame, splats.normals, fromTriangles, i);
    splats.colors = particleColors(frame, settings);
    splats.layers = particleLayers(frame, settings);
    return splats;
}

Mesh splatsToMesh(const Splats& splats, int segments) {
    if (segments < 3) throw std::invalid_argument("splatsToMesh: segments must be at least 3");
    const float rimScale = 1.0f / std::cos(std::numbers::pi_v<float> / float(segments));
    const std::size_t perDisc = std::size_t(segments) + 1;
    Mesh mesh;
    mesh.positions.reserve(splats.centers.size() * perDisc);
    mesh.triangles.reserve(splats.centers.size() * segments);
    for (std::size_t d = 0; d < splats.centers.size(); ++d) {
        const Eigen::Vector3f& n = splats.normals[d];
        const auto [u, v] = discBasis(n);
        const auto base = std::uint32_t(mesh.positions.size());
        mesh.positions.push_back(splats.centers[d]);
        for (int k = 0; k < segments; ++k) {
            const float angle = 2.0f * std::numbers::pi_v<float> * float(k) / float(segments);
            mesh.positions.push_back(splats.centers[d] +
                                     splats.radii[d] * rimScale *
                                         (std::cos(angle) * u + std::sin(angle) * v));
            const auto next = std::uint32_t(1 + (k + 1) % segments);
            mesh.triangles.push_back({base, base + 1 + std::uint32_t(k), base + next});
        }
        mesh.normals.insert(mesh.normals.end(), perDisc, n);
        // Colourless splats (a caller that filled only the geometry) render a neutral grey.
        const Eigen::Vector3f color =
            d < splats.colors.size() ? splats.colors[d] : Eigen::Vector3f::Constant(0.8f);
        mesh.colors.insert(mesh.colors.end(), perDisc, color);
        if (d < splats.layers.size())
            mesh.layers.insert(mesh.layers.end(), perDisc, splats.layers[d]);
    }
    return mesh;
}

}  // namespace rend::render
