#pragma once
// The background grid of the material point method (seeds/002, Section 3): a sparse 3D grid of
// spacing h, with the quadratic B-spline weights w_ip of the particles' stencils (eq. 2 with the
// quadratic spline in place of eq. 4's cubic: 27 nodes a particle). Momentum goes to the grid
// and back with the affine particle-in-cell transfer (APIC, Jiang et al. 2015), which keeps the
// affine part of the velocity field and conserves linear and angular momentum:
//     P2G  m_i = sum_p w_ip m_p,   m_i v_i = sum_p w_ip m_p (v_p + C_p (x_i - x_p)),
//     G2P  v_p = sum_i w_ip v_i,   C_p = 4 / h^2 sum_i w_ip v_i (x_i - x_p)^T,
// (4 / h^2 = D_p^-1 for the quadratic spline). A membrane is one layer of particles in a 3D
// grid, so only the nodes some particle's stencil touches exist: they are numbered through a
// hash of their integer coordinates. A particle's 27 node numbers are kept while its stencil
// stays on the same base node (most steps move a particle a small part of a cell); the
// numbering is dropped and rebuilt every kRenumberEvery transfers. The sums do not depend on
// it: each node adds its particles in particle order.
//
// Determinism: P2G runs serially in particle order (the sums are the same bits for any thread
// count); G2P reads the grid and writes each particle once, in parallel.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace rend::sim {

class MpmGrid {
public:
    /// spacing: the grid's h [m], > 0.
    explicit MpmGrid(double spacing);

    double spacing() const { return h_; }

    /// One APIC round trip at positions x: the particles with onGrid[p] != 0 hand their mass
    /// and momentum (v, C) to the grid and take back the grid's velocity and affine matrix into
    /// v[p] and affine[p]. The others, and any particle too far out for the grid's integer
    /// coordinates (2^20 cells from the origin) or not finite, are left as they are.
    /// `collide`, when given, sees every node's velocity (at the node's position) before it
    /// goes back to the particles: the grid's collision with the ground and colliders.
    using NodeCollision = std::function<void(const Eigen::Vector3d&, Eigen::Vector3d&)>;
    void transfer(std::span<const Eigen::Vector3d> x, std::span<const double> mass,
                  std::span<const std::uint8_t> onGrid, std::span<Eigen::Vector3d> v,
                  std::span<Eigen::Matrix3d> affine, const NodeCollision& collide = {});

    /// Nodes the last transfer used.
    int nodeCount() const { return int(nodeMass_.size()); }
    /// The last transfer's total mass and momentum on the grid (for tests).
    double gridMass() const;
    Eigen::Vector3d gridMomentum() const;

private:
    /// The node numbered for integer coordinates `key` (packed), made if new.
    int nodeAt(std::uint64_t key);
    void grow();
    /// Forgets every node (the next transfer numbers them afresh).
    void clearNodes();
    /// Stencils of the grid particles into stencil_; node numbers into nodes_ for those whose
    /// stencil moved to another base node since the last transfer.
    void buildStencils(std::span<const Eigen::Vector3d> x, std::span<const std::uint8_t> onGrid);
    void particleToGrid(std::span<const double> mass, std::span<const Eigen::Vector3d> v,
                        std::span<const Eigen::Matrix3d> affine);
    /// Node momenta to velocities, collided.
    void nodeVelocities(const NodeCollision& collide);
    void gridToParticle(std::span<Eigen::Vector3d> v, std::span<Eigen::Matrix3d> affine);

    /// Transfers between full renumberings: nodes no particle touches any more pile up as the
    /// sheet moves, and are dropped this often.
    static constexpr int kRenumberEvery = 64;
    struct Stencil {
        Eigen::Vector3d frac;  ///< x / h - base, in [0.5, 1.5) per axis
        int particle;
    };
    double h_;
    std::vector<Stencil> stencil_;  ///< per grid particle, in particle order
    // Per particle (all of them): the base node its nodes_ were numbered for, and whether so.
    std::vector<Eigen::Vector3i> base_;
    std::vector<std::uint8_t> numbered_;
    std::vector<int> nodes_;  ///< per particle, the 27 nodes of its stencil
    std::vector<double> nodeMass_;
    std::vector<Eigen::Vector3d> nodeMomentum_;  ///< then the node's velocity
    std::vector<Eigen::Vector3i> nodeCell_;      ///< the node's integer coordinates
    int transfers_ = 0;
    // Open-addressed hash of node coordinates; a slot is used when its stamp is the current.
    std::vector<std::uint64_t> keys_;
    std::vector<int> ids_;
    std::vector<std::uint32_t> stamps_;
    std::uint32_t stamp_ = 1;
};

}  // namespace rend::sim
