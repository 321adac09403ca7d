#pragma once
// The internal forces of one membrane discretisation. Membrane owns what every solver shares:
// the particles and their lumped masses, the rest lattice and its triangles, boundary
// conditions, gravity, damping, the follower pressure, the integrators with their stable step,
// the blow-up guard, diffusion, the DamageState and the FrameView. A Solver only turns
// positions into forces, and breaks through the DamageState's operations.
//
// Implemented by the peridynamic bonds of the membrane paper (PeridynamicBonds) and by the
// continuum, spring and SPH models of the other papers.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "sim/Bonds.h"
#include "sim/DamageState.h"

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

    /// Breaks, for good, whatever is past its critical strain at x, through the DamageState's
    /// operations (sim/DamageState.h). Nothing breaks by default.
    virtual void fracture(const std::vector<Eigen::Vector3d>& x) {}

    /// One step's forces at x that also move the solver's history on: whatever is past its
    /// critical strain breaks (through the DamageState), whatever yields yields. `v` and `dt`
    /// let a law that stiffens (the power law in compression) look ahead for stiffening(). By
    /// default fracture() then forces().
    virtual void advance(const std::vector<Eigen::Vector3d>& x,
                         const std::vector<Eigen::Vector3d>& v, double dt,
                         std::vector<Eigen::Vector3d>& force) {
        fracture(x);
        forces(x, force);
    }

    /// The worst tangent stiffness over its rest value (>= 1) seen by the last advance(): the
    /// explicit step is cut into pieces so each stays within the rest bound over its square root.
    virtual double stiffening() const { return 1.0; }

    /// Writes into the DamageState, with weaken(), eq. 27's gamma of every bond whose strength
    /// the solver keeps in its own pieces (springs, elements); called once per frame, for the
    /// damage field. Nothing by default: every bond keeps full strength.
    virtual void reportStrength(DamageState& damage) const {}

    /// Set-up, before anything else: the Membrane's bonds and the DamageState the solver reads
    /// in forces() and changes in advance(); both outlive the solver.
    void bind(const BondFamilies& bonds, DamageState& damage) {
        sharedBonds_ = &bonds;
        damage_ = &damage;
        onBind();
        own_.reset();
    }

    /// Carries the notches into the solver's own pieces at set-up: the DamageState already has
    /// the bonds {i, j} in `edges` broken (and their edges).
    virtual void cut(const std::vector<std::array<int, 2>>& edges) {}

    /// The diffusing quantity per particle (empty without diffusion), for the solvers that
    /// couple to it; Membrane sets it before every forces() and fracture().
    void setTheta(std::span<const double> theta) { theta_ = theta; }

protected:
    /// What the solver derives from the bound bonds and damage maps.
    virtual void onBind() {}

    /// A solver built on its own (tests, benches) works on a fresh state of its own over
    /// `bonds` (empty: none) and `triangles` until a Membrane binds its shared one.
    void bindOwn(BondFamilies bonds, int particleCount,
                 std::span<const std::array<int, 3>> triangles) {
        if (bonds.offsets.empty()) bonds.offsets.assign(particleCount + 1, 0);
        auto own = std::make_unique<Own>(Own{std::move(bonds), {}});
        own->damage = DamageState(own->bonds, triangles);
        bind(own->bonds, own->damage);
        own_ = std::move(own);
    }

    std::span<const double> theta_;
    const BondFamilies* sharedBonds_ = nullptr;
    DamageState* damage_ = nullptr;

private:
    struct Own {
        BondFamilies bonds;
        DamageState damage;
    };
    std::unique_ptr<Own> own_;
};

}  // namespace rend::sim
