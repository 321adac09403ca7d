#pragma once
// Seed 004's particle level set (seeds/004, Sec. 4 and 4.3, eqs. 32-36), of a membrane's
// outline (issue 15). The sheet's surface stage can draw its outline as the zero level set
// (`surface = "particle_level_set"`, render/LatticeSurface.h).
//
// A membrane's body is its sheet, so the level set lives on the sheet: Phi is the signed
// distance along the sheet to its boundary, negative inside. Every particle carries Phi, and a
// ring of ghost particles outside the outline carries it there (sim/Lattice.h, ghostBand: the
// sheet's lattice continued past its outline, so the ghosts and the outline particles form
// the band's triangles). At rest Phi is the distance to the scene's outline (a rectangle's
// sides, a disc's circle), not to the outermost particles.
// - Between reinitialisations Phi stays on its particles (eq. 36, dPhi/dt = 0) and each ghost
//   moves with the weighted mean velocity of the particles of its support (seed 004: "the
//   averaged velocity of the particles in the interior of the solid body which are within their
//   kernel support"): its anchor (its nearest particle) and the anchor's neighbours through
//   intact lattice edges, weighted by 1 - r / 2dx in rest distance r from the ghost's site.
// - Every 20th step (seed 004) the level set is reinitialised to a signed distance in the
//   current sheet. The ghosts are first put back on the linear extrapolation of their anchor's
//   neighbourhood (seed 004's other way of assigning them, which the mean velocity drifts from
//   in a spin). The zero set is then the segment where Phi changes sign in each kept band
//   triangle, and, along every broken lattice edge, the crack's crossing on each side (half the
//   rest length from the particle towards the other end). Phi of a particle becomes minus its
//   distance to the zero set, propagated from particle to particle through intact lattice edges
//   only (closest segments handed on, as a vector distance transform), so a crack is a boundary
//   and distance never leaks across it. Beyond three spacings Phi is held at -3 dx (seed 004's
//   narrow band). The band triangles' particles and the ghosts keep their values: they hold the
//   interface, which measuring them again from the piecewise-linear zero set moved inward on a
//   disc (0.27 dx in 50 reinitialisations), the shift seed 004 reports of its own.
// The ghosts' positions and Phi are state (checkpoints and the cache carry them). Membrane
// carries a level set only for a flat sheet whose surface draws it (MembraneParams::
// particleLevelSet); it never changes the motion.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "sim/Params.h"
#include "sim/StateArchive.h"

namespace rend::sim {

class ParticleLevelSet {
public:
    static constexpr int kReinitialiseEvery = 20;  ///< seed 004's "every 20th time step"
    static constexpr double kBand = 3.0;           ///< the narrow band's half-width, in dx

    ParticleLevelSet() = default;
    /// rest: the particles' rest positions; triangles: the rest lattice's; bondOffsets and
    /// bondPartners: the bond families (every lattice edge is a bond).
    ParticleLevelSet(const SheetParams& sheet, std::span<const Eigen::Vector3d> rest,
                     std::span<const std::array<int, 3>> triangles,
                     std::span<const int> bondOffsets, std::span<const int> bondPartners);

    /// Places the ghosts on the sheet at x and reinitialises (after the set-up's notches).
    void start(std::span<const Eigen::Vector3d> x, std::span<const std::uint8_t> alive);

    /// One step done (`step` counts them from 1): the ghosts move with their support's mean
    /// velocity over dt, and every kReinitialiseEvery-th step the level set is reinitialised.
    /// `broken` is the damage's count of broken bonds: when it changes, the band's kept
    /// triangles are updated at once.
    void advance(std::span<const Eigen::Vector3d> x, std::span<const Eigen::Vector3d> v,
                 std::span<const std::uint8_t> alive, std::size_t broken, double dt, long step);

    void reinitialise(std::span<const Eigen::Vector3d> x, std::span<const std::uint8_t> alive);

    std::span<const double> phi() const { return phi_; }
    std::span<const Eigen::Vector3d> ghostPositions() const { return ghost_; }
    std::span<const Eigen::Vector3d> ghostRestPositions() const { return restGhost_; }
    std::span<const double> ghostPhi() const { return ghostPhi_; }
    std::span<const int> ghostAnchors() const { return anchor_; }
    std::span<const std::array<int, 3>> bandTriangles() const { return band_; }
    /// Per band triangle, 1 while its particles and its ghosts' anchors hang together through
    /// intact lattice edges (see keepBand()).
    std::span<const std::uint8_t> bandKept() const { return bandKept_; }

    template <class Self, class Archive>
    static void visitState(Self& s, Archive& a) {
        expectSize(a, s.ghost_.size(), "ghost particles");
        a(s.ghost_), a(s.ghostPhi_), a(s.phi_), a(s.bandKept_);
    }

private:
    /// A piece of the zero level set: the segment from a to b (a point where they are equal).
    struct Segment {
        Eigen::Vector3d a, b;
        double distance(const Eigen::Vector3d& p) const {
            const Eigen::Vector3d ab = b - a;
            const double length2 = ab.squaredNorm();
            const double s = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
            return (p - (a + s * ab)).norm();
        }
    };
    /// A particle of a ghost's support: its bond from the anchor (-1: the anchor) and weight.
    struct Support {
        int particle, bond;
        double weight;
    };
    void findSupports();
    /// Offers particle i a zero-set segment (reinitialise's scratch: distance_, closest_).
    void offer(int i, const Segment& zero, std::span<const Eigen::Vector3d> x);
    /// The outline's and the cracks' zero set, offered to the particles beside it.
    void findZeroSet(std::span<const Eigen::Vector3d> x, std::span<const std::uint8_t> alive);

    /// A lattice edge from a particle: the other end and the bond to it (-1: none).
    struct Neighbour {
        int particle, bond;
    };
    std::span<const Neighbour> neighbours(int i) const {
        return {neighbours_.data() + neighbourOffsets_[i],
                std::size_t(neighbourOffsets_[i + 1] - neighbourOffsets_[i])};
    }
    bool joined(int i, int j, std::span<const std::uint8_t> alive) const;
    /// Joined, or both joined to a common lattice neighbour.
    bool nearlyJoined(int i, int j, std::span<const std::uint8_t> alive) const;
    /// A band triangle is kept while its particles are pairwise joined by intact lattice edges
    /// and each ghost's anchor is one of them or nearly joined to one: so no band triangle spans
    /// a crack that reaches the outline.
    void keepBand(std::span<const std::uint8_t> alive);
    void placeGhosts(std::span<const Eigen::Vector3d> x, std::span<const std::uint8_t> alive);
    /// The least-squares deformation of particle a's intact lattice neighbourhood; false where
    /// it does not span the rest plane.
    bool deformation(int a, std::span<const Eigen::Vector3d> x, std::span<const std::uint8_t> alive,
                     Eigen::Matrix3d& F) const;

    double dx_ = 0.0;
    std::vector<Eigen::Vector3d> rest_;
    std::vector<int> neighbourOffsets_;
    std::vector<Neighbour> neighbours_;
    std::vector<Eigen::Vector3d> restGhost_, ghost_;
    std::vector<double> phi_, ghostPhi_;
    std::vector<int> anchor_;
    std::vector<std::array<int, 3>> band_;
    std::vector<std::uint8_t> bandKept_;
    std::size_t brokenSeen_ = std::size_t(-1);  ///< the broken-bond count keepBand last saw
    std::vector<int> supportOffsets_;
    std::vector<Support> support_;
    // reinitialise()'s scratch, kept between calls: only the narrow band's entries are touched.
    std::vector<double> distance_;
    std::vector<Segment> closest_;
    std::vector<std::uint8_t> holds_;
    std::vector<int> touched_;
};

}  // namespace rend::sim
