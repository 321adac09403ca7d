#pragma once
// The internal forces of one membrane discretisation. Membrane owns what every solver shares:
// the particles and their lumped masses, the rest lattice and its triangles, boundary
// conditions, gravity, damping, the follower pressure, the integrators with their stable step,
// the blow-up guard, diffusion and the FrameView. A Solver only turns positions into forces.
//
// The peridynamic bonds (the membrane paper's model) are Membrane's built-in solver: its force
// loop is compiled per bond law and fused with fracture and diffusion coupling, so it stays in
// Membrane. The continuum and spring models of the other papers implement this interface.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace rend::sim {

class Solver {
public:
    virtual ~Solver() = default;

    /// Internal force on every particle at positions x, overwriting `force` (sized by the
    /// caller). The sum over particles is zero: forces are internal.
    virtual void forces(const std::vector<Eigen::Vector3d>& x,
                        std::vector<Eigen::Vector3d>& force) const = 0;

    /// Per particle, half the absolute row sum of the rest stiffness matrix [N/m] (for springs,
    /// sum_j k_ij): by Gershgorin omega_max^2 <= 2 k_i / m_i, so the explicit schemes are stable
    /// for dt <= sqrt(2 m_i / k_i), the same bound as the peridynamic bonds'.
    virtual std::vector<double> stiffnessRowSums(int particleCount) const = 0;

    /// Stored elastic energy at positions x [J].
    virtual double strainEnergy(const std::vector<Eigen::Vector3d>& x) const = 0;

    /// Breaks, for good, whatever is past its critical strain at x, and returns the rest
    /// lattice's edges {i, j} that came apart in this call, so Membrane can break the matching
    /// bonds (the FrameView, damage and diffusion read those). Nothing breaks by default.
    virtual std::vector<std::array<int, 2>> fracture(const std::vector<Eigen::Vector3d>& x) {
        return {};
    }

    /// Cuts the edges {i, j} at set-up (pre-notches). Returns false when the solver cannot
    /// represent a cut.
    virtual bool cut(const std::vector<std::array<int, 2>>& edges) { return edges.empty(); }

    /// Per rest triangle, 1 while it carries load and 0 once removed; empty when the solver
    /// removes none.
    virtual std::span<const std::uint8_t> triangleAlive() const { return {}; }

    /// The diffusing quantity per particle (empty without diffusion), for the solvers that
    /// couple to it; Membrane sets it before every forces() and fracture().
    void setTheta(std::span<const double> theta) { theta_ = theta; }

protected:
    std::span<const double> theta_;
};

}  // namespace rend::sim
