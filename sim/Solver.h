#pragma once
// The internal forces of one membrane discretisation. Membrane owns what every solver shares:
// the particles and their lumped masses, the rest lattice and its triangles, boundary
// conditions, gravity, damping, the follower pressure, the integrators with their stable step,
// the blow-up guard, diffusion and the FrameView. A Solver only turns positions into forces.
//
// Implemented by the peridynamic bonds of the membrane paper (PeridynamicBonds) and by the
// continuum, spring and SPH models of the other papers.

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

    /// One step's forces at x that also move the solver's history on: whatever is past its
    /// critical strain breaks, whatever yields yields. Returns the rest edges that came apart, as
    /// fracture() does. `v` and `dt` let a law that stiffens (the power law in compression) look
    /// ahead for stiffening(). By default fracture() then forces().
    virtual std::vector<std::array<int, 2>> advance(const std::vector<Eigen::Vector3d>& x,
                                                    const std::vector<Eigen::Vector3d>& v,
                                                    double dt,
                                                    std::vector<Eigen::Vector3d>& force) {
        std::vector<std::array<int, 2>> apart = fracture(x);
        forces(x, force);
        return apart;
    }

    /// The worst tangent stiffness over its rest value (>= 1) seen by the last advance(): the
    /// explicit step is cut into pieces so each stays within the rest bound over its square root.
    virtual double stiffening() const { return 1.0; }

    /// Fraction of strength (eq. 27's gamma) the shared bond b of the Membrane's BondFamilies
    /// still has, for the damage field; 1 unless the solver keeps it per bond.
    virtual double bondStrengthLeft(int bond) const { return 1.0; }

    /// The Membrane's bond families in CSR (bonds of particle i: [offsets[i], offsets[i+1]),
    /// partner j), given once after construction, for a solver whose bondStrengthLeft() must
    /// map a bond onto its own pieces. Ignored by default.
    virtual void bindBonds(std::span<const int> offsets, std::span<const int> partners) {}

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
