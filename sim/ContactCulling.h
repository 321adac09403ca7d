#pragma once
// Which parts of the sheet self-contact has to search at a list build (issue 13): most of a
// sheet is smooth, and a smooth stretch of sheet cannot touch itself.
//
// The rest lattice is cut into tiles (cubes of the rest positions, a few spacings wide). At a
// build, each tile's neighbourhood (itself and the tiles beside it at rest) is fitted with an
// affine map, rest to current, by least squares. Two particles of a neighbourhood not bonded at
// rest were at least `restClearance` apart at rest, so they are now at least
// sigma restClearance - 2 max|r| apart (sigma the map's smallest stretch over the directions the
// rest neighbourhood spans, r the residuals); or, along a path of lattice edges at most
// kEdgePath times their rest distance, sigma s - kEdgePath s m, m the most the residual changes
// per unit rest length along an edge, which passes a sheet stretched unevenly or bent more than
// the first. Only residuals along the fitted plane count. Tiles not beside each other at rest are
// tested by bounding spheres. A tile is active when either test cannot rule out a particle not
// bonded to one of its particles at rest within the reach asked for; a particle of a quiet tile has
// no such particle within it, and the search skips it. A flat, stretched or gently bent sheet is
// quiet; a fold, a crumple, or a flap over another piece is active.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace rend::sim {

class ContactCulling {
public:
    /// `rest`: rest positions; `triangles`: the sheet's; `bondReach2`: the squared rest
    /// distance within which two particles are bonded; `tileSize`: the tiles' edge at rest [m].
    ContactCulling(std::span<const Eigen::Vector3d> rest,
                   std::span<const std::array<int, 3>> triangles, double bondReach2,
                   double tileSize);

    /// The least rest distance from a particle to a particle, or to a point of a triangle, not
    /// bonded to it at rest (none of its corners bonded).
    double restClearance() const { return restClearance_; }

    /// At positions x, sets active[i] = 1 where particle i may have, within `reach`, a particle
    /// or a kept triangle not bonded to it at rest; 2 where it is in a tile beside such a
    /// particle's; else 0. Everything within `reach` of an active particle and not bonded to it
    /// is then an active particle or a kept triangle with a corner marked 1 or 2. Returns the
    /// number of particles marked 1.
    int mark(std::span<const Eigen::Vector3d> x, double reach,
             std::span<const std::array<int, 3>> triangles, std::span<const std::uint8_t> kept,
             std::vector<std::uint8_t>& active) const;

private:
    struct Tile {
        std::vector<int> particles;
        std::vector<int> beside;  ///< tiles within one cell at rest, itself included
        /// The edges (a < b) of the triangles with a corner in the neighbourhood.
        std::vector<std::array<int, 2>> edges;
        /// The neighbourhood at rest: its centre, the pseudo-inverse of its scatter, and an
        /// orthonormal basis of the directions it spans.
        Eigen::Vector3d restCentre = Eigen::Vector3d::Zero();
        Eigen::Matrix3d restInverse = Eigen::Matrix3d::Zero();
        Eigen::MatrixXd span;
        double outOfSpan = 0.0;  ///< the farthest rest particle off the span, from the centre
        int count = 0;           ///< particles in the neighbourhood
        /// The tile's own particles at rest: their centre, the pseudo-inverse of their scatter,
        /// and the farthest from the centre.
        Eigen::Vector3d ownCentre = Eigen::Vector3d::Zero();
        Eigen::Matrix3d ownInverse = Eigen::Matrix3d::Zero();
        double ownRadius = 0.0;
    };
    /// Current moments of one tile: the sum of x, and of x X^T (X at rest).
    struct Moments {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        Eigen::Matrix3d cross = Eigen::Matrix3d::Zero();
    };
    /// A tile's own affine fit at a build: x - x[0] = centre + f (X - ownCentre) + r, |r| <=
    /// residual.
    struct OwnFit {
        Eigen::Vector3d centre = Eigen::Vector3d::Zero();
        Eigen::Matrix3d f = Eigen::Matrix3d::Zero();
        double residual = 0.0;
    };
    OwnFit ownFit(const Tile& tile, const Moments& m, std::span<const Eigen::Vector3d> x) const;
    double residualBound(const Tile& tile, std::span<const OwnFit> own,
                         const Eigen::Vector3d& centre, const Eigen::Matrix3d& f) const;
    void setUpTiles(std::span<const Eigen::Vector3d> rest, double tileSize);
    void setUpOwnFit(Tile& tile, std::span<const Eigen::Vector3d> rest);
    void measureRestClearance(std::span<const Eigen::Vector3d> rest, double bondReach2);
    void measureTriangleClearance(std::span<const Eigen::Vector3d> rest,
                                  std::span<const std::array<int, 3>> triangles, double bondReach2);
    std::vector<double> longestEdges(std::span<const Eigen::Vector3d> x,
                                     std::span<const std::array<int, 3>> triangles,
                                     std::span<const std::uint8_t> kept) const;
    void setUpEdges(std::span<const std::array<int, 3>> triangles);
    bool smooth(const Tile& tile, std::span<const Moments> moments, std::span<const OwnFit> own,
                std::span<const Eigen::Vector3d> x, double reach) const;
    /// The most the residual's part along the plane changes per unit rest length along an edge.
    double residualSlope(const Tile& tile, std::span<const Eigen::Vector3d> x,
                         const Eigen::Matrix3d& f, const Eigen::Matrix3d& along) const;
    void markOverlaps(std::span<const Eigen::Vector3d> x, double reach,
                      std::span<const double> edge, std::vector<std::uint8_t>& tileActive) const;

    bool particlesMeet(std::span<const Eigen::Vector3d> x, int t, int u,
                       const Eigen::Vector3d& centreT, double radiusT,
                       const Eigen::Vector3d& centreU, double radiusU, double gap) const;
    void markNearBigTiles(std::span<const Eigen::Vector3d> x, double reach, double edgeCap,
                          std::span<const double> edge, std::span<const int> big,
                          std::span<const Eigen::Vector3d> centres, std::span<const double> radii,
                          std::vector<std::uint8_t>& tileActive) const;

    std::vector<Eigen::Vector3d> rest_;  ///< relative to restOrigin_
    double restRadius_ = 0.0;            ///< the widest tile's bounding radius at rest
    double restEdge_ = 0.0;              ///< the longest triangle edge at rest
    Eigen::Vector3d restOrigin_ = Eigen::Vector3d::Zero();
    std::vector<Tile> tiles_;
    std::vector<int> tileOf_;  ///< per particle
    double restClearance_ = 0.0;
};

}  // namespace rend::sim
