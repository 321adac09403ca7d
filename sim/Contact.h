#pragma once
// Contact of the membrane with the ground, with kinematic colliders and with itself (issue 13),
// the same for every solver: Membrane calls it around the solver's forces.
//
// - Ground and colliders are kinematic (infinitely heavy): after each drift a particle closer
//   than half the contact thickness to a surface is moved out to that distance, its approaching
//   normal velocity relative to the surface is removed, and Coulomb friction acts on the
//   tangential one with the normal velocity removed as the normal impulse (Bridson, Fedkiw &
//   Anderson, "Robust treatment of collisions, contact and friction for cloth animation",
//   SIGGRAPH 2002, Section 7.1). Nothing ends a step inside a collider or below the ground.
// - Self-contact: a particle repels every kept triangle of the sheet within the contact
//   thickness d whose corners are not bonded to it at rest (farther than the horizon in the rest
//   lattice), pushing the triangle's corners back by barycentric shares, so momentum is kept;
//   and every particle within d not bonded to it at rest. Triangles, not only particles: a sheet
//   would pass between another's particles d = dx / 2 apart (a triangle's centre is dx / sqrt(3)
//   from its corners). Particles too: torn-off bits hold no triangle, and near a crumple two
//   particles just beyond the horizon share no triangle free of bonds to the other. A damped
//   penalty force with Coulomb friction acts on the nearest such triangle and on each particle.
//   A list build first leaves out the parts of the sheet too smooth to touch anything not
//   bonded to them at rest (ContactCulling.h: a flat, stretched or gently bent sheet costs a
//   fit per tile, not a search per particle). For the rest, candidates come from a spatial hash
//   of triangle centroids into a list padded by a skin,
//   rebuilt only once some particle has moved half the skin since, relative to the mean motion,
//   and the affine motion fitted since the build cannot vouch for it either (a sheet drawn
//   apart keeps its list; Contact::staleAfterAffineFit) (a Verlet list); a few particles that
//   outran the skin while the rest did not are followed afresh instead (ContactMovers.cpp). The
//   skin adapts so that a list lasts about 24 steps, up to a cap that leaves the culling room
//   (Contact.cpp). The penalty's stiffness per unit mass is at least the base rate (Membrane:
//   enough to hold a pile of sheets under gravity within d / 4) and grows with the fastest
//   particle's speed, so that no approach at the scene's speeds closes past d / 2.
// - The step limit: with self-contact, no two particles close by more than d / 4 in a step
//   (dt <= d / (4 (2 max|v|))), and no particle moves past half a collider's thinnest part.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "sim/Collider.h"
#include "sim/ColliderDistance.h"
#include "sim/ContactCulling.h"
#include "sim/PointHash.h"

namespace rend::sim {

class Contact {
public:
    /// `thickness`: the contact thickness d (ContactParams' 0 already resolved); `horizon`: the
    /// rest distance within which two particles are bonded; `stiffnessRate`: the penalty
    /// stiffness per unit mass at rest [1/s^2].
    Contact(const ContactParams& params, double thickness, double horizon, double stiffnessRate,
            std::span<const std::array<int, 3>> triangles, std::span<const Eigen::Vector3d> rest);

    double thickness() const { return thickness_; }
    bool selfContact() const { return params_.self.enabled; }
    bool hasColliders() const { return params_.ground.enabled || !params_.colliders.empty(); }

    /// Places every collider at time t (its pose and velocity).
    void place(double t);
    std::span<const ColliderPose> poses() const { return poses_; }
    std::span<const ColliderParams> colliders() const { return params_.colliders; }

    static constexpr double kNoFloor = -std::numeric_limits<double>::infinity();
    /// Where the ground is the only collider, the height below which resolveColliders moves a
    /// free particle; kNoFloor otherwise.
    double groundOnlyFloor() const {
        return params_.ground.enabled && params_.colliders.empty() ? params_.ground.height + offset_
                                                                   : kNoFloor;
    }
    /// What resolveColliders records when it moves no particle (the caller knows it would not).
    void touchNothing() { impulse_.setZero(); }

    /// After a drift to the colliders' current pose: moves the particles for which `free` is
    /// set out of the ground and the colliders, with friction on their velocities. Records each
    /// particle's momentum change (lastImpulse). Particles [first, last) only (last -1: all),
    /// for a decomposed run's slab.
    void resolveColliders(std::vector<Eigen::Vector3d>& x, std::vector<Eigen::Vector3d>& v,
                          std::span<const double> mass, std::span<const std::uint8_t> free,
                          int first = 0, int last = -1);

    /// A grid node's velocity v at `at` against the ground and the colliders (the MPM's grid
    /// collision, sim/Mpm.h): within `reach` of a surface and moving into it, its normal
    /// velocity is removed and friction applies, as for a particle; the node is not moved.
    void resolveNodeVelocity(const Eigen::Vector3d& at, Eigen::Vector3d& v, double reach) const;

    /// The sheet's state at a force evaluation, as self-contact reads it.
    struct SheetState {
        std::span<const Eigen::Vector3d> x, v, rest;
        std::span<const double> mass;
        std::span<const std::uint8_t> kept;  ///< per triangle; empty: all kept
        double dt = 0.0;
    };
    /// Adds the self-contact forces to `force`.
    void addSelfContactForces(const SheetState& sheet, std::vector<Eigen::Vector3d>& force);

    /// Whether stepLimit can be finite: self-contact or a collider (the ground sets no limit).
    bool limitsStep() const { return params_.self.enabled || !params_.colliders.empty(); }
    /// The longest step the contact allows with particles moving at most `maxSpeed`.
    double stepLimit(double maxSpeed) const;

    /// A bound on the work moving colliders did on the sheet since the last call [J]: each
    /// impulse times the fastest collider point's speed. The blow-up guard's budget takes it.
    double takeWork() {
        const double w = work_;
        work_ = 0.0;
        return w;
    }
    /// Drops the self-contact's candidate list: the next force evaluation builds a fresh one.
    /// Called at every frame's start, so that a checkpoint, which keeps no list, resumes with
    /// the same bits as a run that never stopped.
    void expireList() { builtAt_.clear(); }
    /// What a checkpoint keeps (sim/StateArchive.h): the skin's history and the colliders'
    /// work; the list itself is expired at each frame's start (expireList).
    template <class Self, class Archive>
    static void visitState(Self& s, Archive& a) {
        a(s.skin_), a(s.evaluations_), a(s.builtAtEvaluation_), a(s.builds_);
        a(s.moverEvaluations_), a(s.work_), a(s.impulse_);
    }
    /// The momentum the ground and colliders gave the sheet in the last resolve [N s].
    Eigen::Vector3d lastImpulse() const { return impulse_; }
    /// Contacts within d at the last force evaluation: particle-triangle ones, and
    /// particle-particle ones counted from both ends.
    std::size_t lastPairCount() const { return pairs_; }
    /// Candidate-list rebuilds so far, and the wall seconds they took.
    long listBuilds() const { return builds_; }
    double listBuildSeconds() const { return buildSeconds_; }
    /// Force evaluations that kept the list and followed movers (ContactMovers.cpp) instead.
    long moverEvaluations() const { return moverEvaluations_; }
    /// Particles the last build searched (the rest were certified apart from anything not
    /// bonded to them at rest).
    int lastSearched() const { return lastActive_; }

private:
    /// Moves particle i out of one surface (signed distance `s` at x, outward normal) and applies
    /// friction against the surface's velocity there.
    void pushOut(Eigen::Vector3d& x, Eigen::Vector3d& v, const SurfaceDistance& s,
                 const Eigen::Vector3d& surfaceVelocity, const Friction& friction) const;
    void resolveParticle(Eigen::Vector3d& x, Eigen::Vector3d& v) const;
    /// One particle's contact with its nearest triangle: the force on the particle, and the
    /// triangle that takes it back by barycentric shares; and its contacts with particles.
    struct PointContact {
        int triangle = -1;
        Eigen::Vector3d weights = Eigen::Vector3d::Zero();
        Eigen::Vector3d force = Eigen::Vector3d::Zero();
        Eigen::Vector3d pointForce = Eigen::Vector3d::Zero();  ///< from particles within d
        int points = 0;
    };
    void setUpTriangles(std::span<const std::array<int, 3>> triangles,
                        std::span<const Eigen::Vector3d> rest, double reach);
    /// Whether the list may have left out something now within d; records drift_.
    bool listStale(std::span<const Eigen::Vector3d> x);
    /// The list's guarantee under the affine motion fitted since the build (see listStale).
    bool staleAfterAffineFit(std::span<const Eigen::Vector3d> x, const Eigen::Vector3d& mean) const;
    void fitBuiltPositions();
    void sizeNextSkin();
    void buildList(const SheetState& s);
    /// A candidate of a build: a kept triangle (>= 0) or a particle (-1 - index), and its
    /// distance from the particle at the build (particles: 0).
    struct Candidate {
        int particle, target;
        double distance;
    };
    /// The candidates found by each thread, in particle order, as the CSR list.
    void storeList(int n, std::span<const std::vector<Candidate>> found);
    /// A list build's hash of some of the kept triangles' centroids (`which`, indices into
    /// centres, radii and kept), queried within reach of a triangle's nearest point, with what a
    /// query reads of each triangle stored in the hash's own order.
    struct TriangleHash {
        struct Item {
            Eigen::Vector3d restCentre, centre;
            double radius;
            int triangle;
        };
        TriangleHash(const Contact& contact, std::span<const int> which,
                     std::span<const Eigen::Vector3d> centres, std::span<const double> radii,
                     std::span<const int> kept, double reach);
        static std::vector<Eigen::Vector3d> gather(std::span<const int> which,
                                                   std::span<const Eigen::Vector3d> all);
        static double widestOf(std::span<const int> which, std::span<const double> radii);
        PointHash hash;
        std::vector<Item> items;
    };
    /// Candidates of particle i within `reach`, appended to out (ascending bucket, triangle).
    void collectCandidates(int i, const SheetState& s, double reach, std::vector<int>& out) const;
    bool bondedAtRest(int i, const std::array<int, 3>& tri,
                      std::span<const Eigen::Vector3d> rest) const;
    std::uint32_t bucketOf(const Eigen::Vector3i& cell) const;
    /// Particle i against its list and `extra` (candidates of this evaluation, found afresh).
    /// kMovers: skip what the movers' fresh candidates cover instead (ContactMovers.cpp).
    template <bool kMovers>
    PointContact nearestContact(int i, const SheetState& s, std::span<const int> extra) const;
    /// Whether triangle t is nearer particle i than `best` (squared); if so, records it.
    void considerTriangle(int i, int t, const SheetState& s, double& best, PointContact& contact,
                          Eigen::Vector3d& closest) const;
    void considerPoint(int i, int j, const SheetState& s, PointContact& contact) const;

    // ---- movers (ContactMovers.cpp) ----
    /// Sets movers_ to the particles that drifted more than skin / 2 from `centre` since the
    /// build, and drift_ to the most any other did; false (and no movers) when they are too many.
    bool findMovers(std::span<const Eigen::Vector3d> x, const Eigen::Vector3d& centre);
    void clearMovers();
    /// This evaluation's candidates of the movers and of their triangles, found afresh, and
    /// the evaluation's particles with them (order_, orderExtra_, extra_).
    void findMoverCandidates(const SheetState& s);
    void addMoverTriangleCandidates(const SheetState& s, std::vector<std::array<int, 2>>& pairs);
    /// Hashes of every particle and kept triangle at the build's positions, built at most once
    /// a build, when movers first appear.
    void buildMoverHashes(const SheetState& s);
    /// The kept triangles `which` split by size: the usual, and the stretched (kStretchedTriangle).
    std::array<std::vector<int>, 2> splitStretched(std::span<const double> radii) const;
    Eigen::Vector3d contactForce(int i, const std::array<int, 3>& tri, const Eigen::Vector3d& w,
                                 const Eigen::Vector3d& closest, const SheetState& s) const;

    ContactParams params_;
    double thickness_ = 0.0, offset_ = 0.0;  ///< d, and d / 2 off collider surfaces
    double restExclusion2_ = 0.0;            ///< squared rest distance of bonded neighbours
    double baseStiffnessRate_ = 0.0;         ///< at rest: holds a pile's weight
    double stiffnessRate_ = 0.0, dampingRate_ = 0.0;   ///< this evaluation's, from the speeds
    std::vector<std::optional<MeshDistance>> meshes_;  ///< per collider, for meshes
    std::vector<ColliderPose> poses_;
    std::vector<double> colliderReach2_;  ///< per collider: (bounding radius + offset)^2
    Eigen::Vector3d impulse_ = Eigen::Vector3d::Zero();  ///< the last resolve's momentum change
    double work_ = 0.0;                                  ///< takeWork's sum
    /// The fastest collider point at the current poses [m/s].
    double colliderSpeed() const;

    // Verlet list of candidate triangles per particle (CSR), built from a spatial hash of the
    // triangles' centroids with cells of twice the search reach.
    std::vector<std::array<int, 3>> triangles_;
    /// Rest centroids, and the squared rest distances from one within which every corner, or
    /// beyond which no corner, is bonded to a particle: one test decides most triangles.
    std::vector<Eigen::Vector3d> restCentres_;
    double allBonded2_ = 0.0, noneBonded2_ = 0.0;
    double restWidest_ = 0.0;  ///< the largest distance from a rest centroid to its corners
    double skin_ = 0.0, skinCap_ = 0.0;
    /// Finds the parts of the sheet a build has to search (ContactCulling.h).
    std::optional<ContactCulling> culling_;
    double buildSeconds_ = 0.0;
    int lastActive_ = 0;                            ///< particles searched at the last build
    long evaluations_ = 0, builtAtEvaluation_ = 0;  ///< force evaluations: all, at the last build
    std::vector<Eigen::Vector3d> builtAt_;          ///< positions at the last build
    /// The build positions' centre, and the pseudo-inverse of their scatter matrix with an
    /// orthonormal basis of the directions it spans (a flat sheet spans two).
    Eigen::Vector3d builtCentre_ = Eigen::Vector3d::Zero();
    Eigen::Matrix3d builtScatterInverse_ = Eigen::Matrix3d::Zero();
    Eigen::MatrixXd builtSpan_;
    std::vector<int> listStart_, list_;
    /// Per list entry: its distance at the build, rounded down (triangles; particles 0).
    std::vector<float> listDistance_;
    /// The most a particle has moved since the build relative to a common displacement [m].
    double drift_ = 0.0;
    /// The mean displacement since the build at the last two evaluations (listStale).
    std::array<Eigen::Vector3d, 2> lastMean_{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    std::vector<int> listed_;  ///< the particles whose lists are not empty, ascending
    /// Movers: particles that drifted more than skin / 2 since the build while the rest did not.
    /// Their candidates, and those of particles near their triangles, are found afresh at each
    /// evaluation (ContactMovers.cpp), and the list is kept for the rest.
    std::vector<int> movers_;                 ///< ascending
    std::vector<std::uint8_t> isMover_;       ///< per particle
    std::vector<int> moverTriangles_;         ///< kept triangles with a mover corner, ascending
    std::vector<std::uint8_t> touchesMover_;  ///< per triangle
    Eigen::Vector3d moverCentre_ = Eigen::Vector3d::Zero();   ///< the common displacement
    std::vector<int> vertexTriangleStart_, vertexTriangles_;  ///< each particle's triangles
    std::unique_ptr<TriangleHash> allUsual_, allStretched_;   ///< buildMoverHashes
    std::unique_ptr<PointHash> allPoints_;
    double allPointsReach_ = 0.0;
    /// The particles evaluated (listed or with fresh candidates), ascending, and each one's
    /// fresh candidates (CSR into extra_; targets as in list_).
    std::vector<int> order_, orderExtra_, extra_;
    std::vector<PointContact> contacts_;  ///< per listed particle, this evaluation's
    std::size_t pairs_ = 0;
    long builds_ = 0, moverEvaluations_ = 0;
};

}  // namespace rend::sim
