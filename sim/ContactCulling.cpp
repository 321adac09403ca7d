#include "sim/ContactCulling.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "sim/ColliderDistance.h"
#include "sim/Parallel.h"
#include "sim/PointHash.h"

namespace rend::sim {
namespace {

using Cell = std::tuple<int, int, int>;

/// A neighbourhood's direction whose spread at rest is below this fraction of its widest is left
/// out of its fit.
constexpr double kThinSpan = 0.1;
/// A tile whose bounding sphere or longest edge has grown past this many times its rest size is
/// handled by its box (markNearBigTiles), not by the spheres' hash.
constexpr double kBigTile = 2.0;
/// Two particles of the lattices rend builds (hexagonal, square with diagonals, the geodesic
/// sphere) are joined by a path of triangle edges at most this times their rest distance long
/// (the square lattice's worst case, across its diagonals).
constexpr double kEdgePath = 1.4142135623730951;

/// The pseudo-inverse of a scatter matrix over the directions it spans, leaving out those whose
/// spread is below kThinSpan of the widest (a flat sheet's seeded jitter), and those directions.
Eigen::Matrix3d spannedInverse(const Eigen::Matrix3d& scatter, std::vector<Eigen::Vector3d>* span) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
    const double largest = eigen.eigenvalues().maxCoeff();
    Eigen::Matrix3d inverse = Eigen::Matrix3d::Zero();
    for (int k = 0; k < 3; ++k) {
        const double lambda = eigen.eigenvalues()[k];
        if (!(largest > 0.0) || lambda <= kThinSpan * kThinSpan * largest) continue;
        const Eigen::Vector3d q = eigen.eigenvectors().col(k);
        inverse += q * q.transpose() / lambda;
        if (span) span->push_back(q);
    }
    return inverse;
}

Cell cellOf(const Eigen::Vector3d& x, double size) {
    const Eigen::Vector3i c = (x / size).array().floor().cast<int>();
    return {c.x(), c.y(), c.z()};
}

}  // namespace

ContactCulling::ContactCulling(std::span<const Eigen::Vector3d> rest,
                               std::span<const std::array<int, 3>> triangles, double bondReach2,
                               double tileSize) {
    if (!rest.empty()) restOrigin_ = rest[0];
    rest_.reserve(rest.size());
    for (const Eigen::Vector3d& p : rest) rest_.push_back(p - restOrigin_);
    setUpTiles(rest_, tileSize);
    measureRestClearance(rest_, bondReach2);
    measureTriangleClearance(rest_, triangles, bondReach2);
    setUpEdges(triangles);
}

void ContactCulling::setUpEdges(std::span<const std::array<int, 3>> triangles) {
    std::vector<std::vector<int>> touching(tiles_.size());  // triangles with a corner in a tile
    for (std::size_t t = 0; t < triangles.size(); ++t)
        for (const int c : triangles[t]) {
            std::vector<int>& list = touching[std::size_t(tileOf_[std::size_t(c)])];
            if (list.empty() || list.back() != int(t)) list.push_back(int(t));
        }
    for (const auto& tri : triangles)
        for (int k = 0; k < 3; ++k)
            restEdge_ = std::max(
                restEdge_,
                (rest_[std::size_t(tri[k])] - rest_[std::size_t(tri[(k + 1) % 3])]).norm());
    for (Tile& tile : tiles_) {
        for (const int b : tile.beside)
            for (const int t : touching[std::size_t(b)]) {
                const auto& tri = triangles[std::size_t(t)];
                for (int k = 0; k < 3; ++k)
                    tile.edges.push_back(
                        {std::min(tri[k], tri[(k + 1) % 3]), std::max(tri[k], tri[(k + 1) % 3])});
            }
        std::sort(tile.edges.begin(), tile.edges.end());
        tile.edges.erase(std::unique(tile.edges.begin(), tile.edges.end()), tile.edges.end());
    }
}

void ContactCulling::setUpTiles(std::span<const Eigen::Vector3d> rest, double tileSize) {
    std::map<Cell, int> index;
    for (std::size_t i = 0; i < rest.size(); ++i) {
        const auto [at, added] = index.try_emplace(cellOf(rest[i], tileSize), int(tiles_.size()));
        if (added) tiles_.emplace_back();
        tiles_[std::size_t(at->second)].particles.push_back(int(i));
        tileOf_.push_back(at->second);
    }
    for (Tile& tile : tiles_) {
        Eigen::Vector3d c = Eigen::Vector3d::Zero();
        for (const int i : tile.particles) c += rest[std::size_t(i)];
        c /= double(tile.particles.size());
        for (const int i : tile.particles)
            restRadius_ = std::max(restRadius_, (rest[std::size_t(i)] - c).norm());
    }
    for (const auto& [cell, t] : index) {
        Tile& tile = tiles_[std::size_t(t)];
        const auto [cx, cy, cz] = cell;
        for (int z = -1; z <= 1; ++z)
            for (int y = -1; y <= 1; ++y)
                for (int x = -1; x <= 1; ++x)
                    if (const auto it = index.find({cx + x, cy + y, cz + z}); it != index.end())
                        tile.beside.push_back(it->second);
        std::sort(tile.beside.begin(), tile.beside.end());
    }
    for (Tile& tile : tiles_) {
        Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
        for (const int b : tile.beside)
            for (const int i : tiles_[std::size_t(b)].particles) {
                tile.restCentre += rest[std::size_t(i)];
                ++tile.count;
            }
        tile.restCentre /= double(tile.count);
        for (const int b : tile.beside)
            for (const int i : tiles_[std::size_t(b)].particles) {
                const Eigen::Vector3d c = rest[std::size_t(i)] - tile.restCentre;
                scatter += c * c.transpose();
            }
        // A direction the neighbourhood hardly spans is left out of the fit; its extent shortens
        // the rest clearance instead (smooth).
        std::vector<Eigen::Vector3d> span;
        tile.restInverse = spannedInverse(scatter, &span);
        tile.span.resize(3, Eigen::Index(span.size()));
        for (std::size_t k = 0; k < span.size(); ++k) tile.span.col(Eigen::Index(k)) = span[k];
        const Eigen::Matrix3d across =
            Eigen::Matrix3d::Identity() - tile.span * tile.span.transpose();
        for (const int b : tile.beside)
            for (const int i : tiles_[std::size_t(b)].particles)
                tile.outOfSpan = std::max(
                    tile.outOfSpan, (across * (rest[std::size_t(i)] - tile.restCentre)).norm());
        setUpOwnFit(tile, rest);
    }
}

void ContactCulling::setUpOwnFit(Tile& tile, std::span<const Eigen::Vector3d> rest) {
    for (const int i : tile.particles) tile.ownCentre += rest[std::size_t(i)];
    tile.ownCentre /= double(tile.particles.size());
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (const int i : tile.particles) {
        const Eigen::Vector3d c = rest[std::size_t(i)] - tile.ownCentre;
        scatter += c * c.transpose();
        tile.ownRadius = std::max(tile.ownRadius, c.norm());
    }
    tile.ownInverse = spannedInverse(scatter, nullptr);
}

// The least rest distance between particles not bonded at rest, searched within twice the bond
// reach (farther pairs are at least that far apart, so the search's radius bounds it).
void ContactCulling::measureRestClearance(std::span<const Eigen::Vector3d> rest,
                                          double bondReach2) {
    const double radius = 2.0 * std::sqrt(bondReach2);
    const PointHash hash(rest, radius);
    const int n = int(rest.size());
    double least = radius * radius;
#pragma omp parallel for schedule(static) reduction(min : least) if (n >= kParallelThreshold)
    for (int i = 0; i < n; ++i)
        hash.near(rest[std::size_t(i)], [&](int j) {
            const double r2 = (rest[std::size_t(i)] - rest[std::size_t(j)]).squaredNorm();
            if (r2 > bondReach2) least = std::min(least, r2);
        });
    restClearance_ = std::sqrt(least);
}

// Lowered to the least rest distance from a particle to a triangle none of whose corners is
// bonded to it (on a hexagonal lattice the same as between particles; the triangles only need
// searching up to the particles' clearance).
void ContactCulling::measureTriangleClearance(std::span<const Eigen::Vector3d> rest,
                                              std::span<const std::array<int, 3>> triangles,
                                              double bondReach2) {
    std::vector<Eigen::Vector3d> centres(triangles.size());
    double widest = 0.0;
    for (std::size_t t = 0; t < triangles.size(); ++t) {
        const auto& [a, b, c] = triangles[t];
        centres[t] = (rest[std::size_t(a)] + rest[std::size_t(b)] + rest[std::size_t(c)]) / 3.0;
        for (const int k : triangles[t])
            widest = std::max(widest, (rest[std::size_t(k)] - centres[t]).norm());
    }
    if (centres.empty()) return;
    const PointHash hash(centres, restClearance_ + widest);
    const int n = int(rest.size());
    double least = restClearance_ * restClearance_;
#pragma omp parallel for schedule(static) reduction(min : least) if (n >= kParallelThreshold)
    for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d& p = rest[std::size_t(i)];
        hash.near(p, [&](int t) {
            const auto& tri = triangles[std::size_t(t)];
            for (const int k : tri)
                if ((p - rest[std::size_t(k)]).squaredNorm() <= bondReach2) return;
            const Eigen::Vector3d &a = rest[std::size_t(tri[0])], &b = rest[std::size_t(tri[1])],
                                  &c = rest[std::size_t(tri[2])];
            least = std::min(least, (p - closestOnTriangle(p, a, b, c).at(a, b, c)).squaredNorm());
        });
    }
    restClearance_ = std::sqrt(least);
}

// Per tile, the longest edge of the kept triangles with a corner in it: every point of such a
// triangle is within it of each of its corners.
std::vector<double> ContactCulling::longestEdges(std::span<const Eigen::Vector3d> x,
                                                 std::span<const std::array<int, 3>> triangles,
                                                 std::span<const std::uint8_t> kept) const {
    std::vector<double> reach2(tiles_.size(), 0.0);
    for (std::size_t t = 0; t < triangles.size(); ++t) {
        if (!kept.empty() && !kept[t]) continue;
        const auto& [a, b, c] = triangles[t];
        const double longest = std::max({(x[std::size_t(a)] - x[std::size_t(b)]).squaredNorm(),
                                         (x[std::size_t(b)] - x[std::size_t(c)]).squaredNorm(),
                                         (x[std::size_t(c)] - x[std::size_t(a)]).squaredNorm()});
        for (const int corner : triangles[t]) {
            double& r2 = reach2[std::size_t(tileOf_[std::size_t(corner)])];
            r2 = std::max(r2, longest);
        }
    }
    for (double& r : reach2) r = std::sqrt(r);
    return reach2;
}

int ContactCulling::mark(std::span<const Eigen::Vector3d> x, double reach,
                         std::span<const std::array<int, 3>> triangles,
                         std::span<const std::uint8_t> kept,
                         std::vector<std::uint8_t>& active) const {
    const int tiles = int(tiles_.size());
    const std::vector<double> edge = longestEdges(x, triangles, kept);
    const Eigen::Vector3d origin = x.empty() ? Eigen::Vector3d::Zero() : x[0];
    std::vector<Moments> moments(tiles_.size());
    forEachIndex(tiles >= kParallelThreshold / 16, 0, tiles, [&](int t) {
        Moments& m = moments[std::size_t(t)];
        for (const int i : tiles_[std::size_t(t)].particles) {
            const Eigen::Vector3d p = x[std::size_t(i)] - origin;
            m.sum += p;
            m.cross += p * rest_[std::size_t(i)].transpose();
        }
    });
    std::vector<OwnFit> own(tiles_.size());
    forEachIndex(tiles >= kParallelThreshold / 16, 0, tiles, [&](int t) {
        own[std::size_t(t)] = ownFit(tiles_[std::size_t(t)], moments[std::size_t(t)], x);
    });
    std::vector<std::uint8_t> tileActive(std::size_t(tiles), 0);
    forEachIndex(tiles >= kParallelThreshold / 16, 0, tiles, [&](int t) {
        tileActive[std::size_t(t)] = !smooth(tiles_[std::size_t(t)], moments, own, x, reach);
    });
    markOverlaps(x, reach, edge, tileActive);
    // What the search lists for: the active tiles' particles (1); the triangles it lists from
    // have a corner in an active tile or one beside it (2).
    active.assign(x.size(), 0);
    int count = 0;
    for (int t = 0; t < tiles; ++t) {
        if (!tileActive[std::size_t(t)]) continue;
        for (const int b : tiles_[std::size_t(t)].beside)
            for (const int i : tiles_[std::size_t(b)].particles)
                active[std::size_t(i)] = std::max<std::uint8_t>(active[std::size_t(i)], 2);
        count += int(tiles_[std::size_t(t)].particles.size());
    }
    for (int t = 0; t < tiles; ++t)
        if (tileActive[std::size_t(t)])
            for (const int i : tiles_[std::size_t(t)].particles) active[std::size_t(i)] = 1;
    return count;
}

// The tile's own fit, by the moments mark has just summed, and its largest residual (x relative
// to x[0], as the moments).
ContactCulling::OwnFit ContactCulling::ownFit(const Tile& tile, const Moments& m,
                                              std::span<const Eigen::Vector3d> x) const {
    OwnFit fit;
    fit.centre = m.sum / double(tile.particles.size());
    fit.f = (m.cross - double(tile.particles.size()) * fit.centre * tile.ownCentre.transpose()) *
            tile.ownInverse;
    double most = 0.0;  // squared
    for (const int i : tile.particles)
        most = std::max(most, (x[std::size_t(i)] - x[0] - fit.centre -
                               fit.f * (rest_[std::size_t(i)] - tile.ownCentre))
                                  .squaredNorm());
    fit.residual = std::sqrt(most);
    return fit;
}

// A bound on the neighbourhood's residuals from its tiles' own fits, without visiting a
// particle: for particle i of tile b, exactly,
//   r_i = r_i^b + [c_b - centre - F (ownCentre_b - restCentre)] + (F_b - F) (X_i - ownCentre_b),
// so |r_i| <= max|r^b| + |that shift| + |F_b - F|_Frobenius ownRadius_b.
double ContactCulling::residualBound(const Tile& tile, std::span<const OwnFit> own,
                                     const Eigen::Vector3d& centre,
                                     const Eigen::Matrix3d& f) const {
    double bound = 0.0;
    for (const int b : tile.beside) {
        const OwnFit& o = own[std::size_t(b)];
        const Tile& part = tiles_[std::size_t(b)];
        const Eigen::Vector3d shift = o.centre - centre - f * (part.ownCentre - tile.restCentre);
        bound = std::max(bound, o.residual + shift.norm() + (o.f - f).norm() * part.ownRadius);
    }
    return bound;
}

// The neighbourhood's affine fit x = centre + F (X - restCentre) + r: quiet when
// sigma restClearance - 2 max|r| >= reach.
bool ContactCulling::smooth(const Tile& tile, std::span<const Moments> moments,
                            std::span<const OwnFit> own, std::span<const Eigen::Vector3d> x,
                            double reach) const {
    if (tile.span.cols() == 0) return true;  // a single particle
    Moments sum;
    for (const int b : tile.beside) {
        sum.sum += moments[std::size_t(b)].sum;
        sum.cross += moments[std::size_t(b)].cross;
    }
    const Eigen::Vector3d centre = sum.sum / double(tile.count);
    const Eigen::Matrix3d f =
        (sum.cross - double(tile.count) * centre * tile.restCentre.transpose()) * tile.restInverse;
    const Eigen::MatrixXd image = f * tile.span;
    const Eigen::MatrixXd gram = image.transpose() * image;
    const double sigma = std::sqrt(
        std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(gram, Eigen::EigenvaluesOnly)
                          .eigenvalues()
                          .minCoeff()));
    // Two rest points of the neighbourhood restClearance apart are at least clearance apart
    // within its span.
    const double outOfSpan = 2.0 * tile.outOfSpan;
    const double clearance =
        std::sqrt(std::max(0.0, restClearance_ * restClearance_ - outOfSpan * outOfSpan));
    const double allowed = 0.5 * (sigma * clearance - reach);  // on max|r|
    if (allowed <= 0.0) return false;                          // no residual bound can pass either
    if (residualBound(tile, own, centre, f) <= allowed) return true;  // no particle visited
    // A sheet's neighbourhood maps onto a plane: residuals across it (waves, jitter, a gentle
    // bend) only move points apart, |x_i - x_j|^2 = |F dX + dr_along|^2 + dr_across^2, so only
    // the part along the plane counts.
    Eigen::Matrix3d along = Eigen::Matrix3d::Identity();
    if (image.cols() == 2) {
        const Eigen::Vector3d normal =
            Eigen::Vector3d(image.col(0)).cross(Eigen::Vector3d(image.col(1))).normalized();
        along -= normal * normal.transpose();
    }
    const Eigen::Vector3d origin = x[0];
    bool within = true;
    for (std::size_t b = 0; within && b < tile.beside.size(); ++b)
        for (const int i : tiles_[std::size_t(tile.beside[b])].particles) {
            const Eigen::Vector3d r =
                x[std::size_t(i)] - origin - centre - f * (rest_[std::size_t(i)] - tile.restCentre);
            if ((along * r).squaredNorm() > allowed * allowed) {
                within = false;
                break;
            }
        }
    return within || (sigma - kEdgePath * residualSlope(tile, x, f, along)) * clearance >= reach;
}

double ContactCulling::residualSlope(const Tile& tile, std::span<const Eigen::Vector3d> x,
                                     const Eigen::Matrix3d& f, const Eigen::Matrix3d& along) const {
    double slope = 0.0;  // squared
    for (const auto& [a, b] : tile.edges) {
        const Eigen::Vector3d restEdge = rest_[std::size_t(a)] - rest_[std::size_t(b)];
        const Eigen::Vector3d change =
            along * (x[std::size_t(a)] - x[std::size_t(b)] - f * restEdge);
        slope = std::max(slope, change.squaredNorm() / restEdge.squaredNorm());
    }
    return std::sqrt(slope);
}

// Tiles not beside each other at rest, by bounding spheres about their particles' mean.
void ContactCulling::markOverlaps(std::span<const Eigen::Vector3d> x, double reach,
                                  std::span<const double> edge,
                                  std::vector<std::uint8_t>& tileActive) const {
    const int tiles = int(tiles_.size());
    std::vector<Eigen::Vector3d> centres(tiles_.size());
    std::vector<double> radii(std::size_t(tiles), 0.0);
    for (int t = 0; t < tiles; ++t) {
        const std::vector<int>& own = tiles_[std::size_t(t)].particles;
        Eigen::Vector3d c = Eigen::Vector3d::Zero();
        for (const int i : own) c += x[std::size_t(i)];
        c /= double(own.size());
        double r2 = 0.0;
        for (const int i : own) r2 = std::max(r2, (x[std::size_t(i)] - c).squaredNorm());
        centres[std::size_t(t)] = c;
        radii[std::size_t(t)] = std::sqrt(r2);
    }
    // A tile torn apart or stretched far beyond its rest size would widen every query; those
    // few are made active with every tile near their box instead.
    const double radiusCap = kBigTile * restRadius_, edgeCap = kBigTile * restEdge_;
    std::vector<int> small, big;
    std::vector<Eigen::Vector3d> smallCentres;
    for (int t = 0; t < tiles; ++t) {
        if (radii[std::size_t(t)] > radiusCap || edge[std::size_t(t)] > edgeCap) {
            big.push_back(t);
            continue;
        }
        small.push_back(t);
        smallCentres.push_back(centres[std::size_t(t)]);
    }
    const PointHash hash(smallCentres, 2.0 * radiusCap + reach + edgeCap);
    forEachIndex(tiles >= kParallelThreshold / 16, 0, int(small.size()), [&](int k) {
        const int t = small[std::size_t(k)];
        if (tileActive[std::size_t(t)]) return;
        const std::vector<int>& beside = tiles_[std::size_t(t)].beside;
        hash.near(centres[std::size_t(t)], [&](int item) {
            const int u = small[std::size_t(item)];
            if (tileActive[std::size_t(t)] || std::binary_search(beside.begin(), beside.end(), u))
                return;
            const double gap = reach + std::max(edge[std::size_t(t)], edge[std::size_t(u)]);
            if (particlesMeet(x, t, u, centres[std::size_t(t)], radii[std::size_t(t)],
                              centres[std::size_t(u)], radii[std::size_t(u)], gap))
                tileActive[std::size_t(t)] = 1;
        });
    });
    markNearBigTiles(x, reach, edgeCap, edge, big, centres, radii, tileActive);
}

// Whether a particle of tile t comes within `gap` of one of tile u: the spheres first, then the
// particles near u's sphere (the same answer from either tile).
bool ContactCulling::particlesMeet(std::span<const Eigen::Vector3d> x, int t, int u,
                                   const Eigen::Vector3d& centreT, double radiusT,
                                   const Eigen::Vector3d& centreU, double radiusU,
                                   double gap) const {
    const double apart = radiusT + radiusU + gap;
    if ((centreT - centreU).squaredNorm() >= apart * apart) return false;
    const double toSphere = radiusU + gap;
    for (const int i : tiles_[std::size_t(t)].particles) {
        if ((x[std::size_t(i)] - centreU).squaredNorm() >= toSphere * toSphere) continue;
        for (const int j : tiles_[std::size_t(u)].particles)
            if ((x[std::size_t(i)] - x[std::size_t(j)]).squaredNorm() < gap * gap) return true;
    }
    return false;
}

void ContactCulling::markNearBigTiles(std::span<const Eigen::Vector3d> x, double reach,
                                      double edgeCap, std::span<const double> edge,
                                      std::span<const int> big,
                                      std::span<const Eigen::Vector3d> centres,
                                      std::span<const double> radii,
                                      std::vector<std::uint8_t>& tileActive) const {
    if (big.empty()) return;
    std::vector<Eigen::AlignedBox3d> boxes;
    for (const int b : big) {
        Eigen::AlignedBox3d box;
        for (const int i : tiles_[std::size_t(b)].particles) box.extend(x[std::size_t(i)]);
        const double gap = reach + std::max(edge[std::size_t(b)], edgeCap);
        box.extend(box.min() - Eigen::Vector3d::Constant(gap));
        box.extend(box.max() + Eigen::Vector3d::Constant(gap));
        boxes.push_back(box);
        tileActive[std::size_t(b)] = 1;
    }
    const int tiles = int(tiles_.size());
    forEachIndex(tiles >= kParallelThreshold / 16, 0, tiles, [&](int t) {
        for (std::size_t k = 0; !tileActive[std::size_t(t)] && k < boxes.size(); ++k)
            if (boxes[k].squaredExteriorDistance(centres[std::size_t(t)]) <
                radii[std::size_t(t)] * radii[std::size_t(t)])
                tileActive[std::size_t(t)] = 1;
    });
}

}  // namespace rend::sim
