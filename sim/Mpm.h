#pragma once
// The enhanced material point method of seeds/002 for heterogeneous elastic materials, made
// codimensional for a membrane (as MPM does for cloth: Jiang et al. 2017).
//
// Formulation. A membrane has no volume for a grid to measure its deformation, so the in-plane
// elastic forces come from the sheet's own lattice: each particle's domain is its share of the
// rest triangles, and the forces on it are seed 002's eq. 20, f = -sum V0 P grad N over the
// domain, with the constant-strain triangles and laws of the FEM solver (sim/FemCst.h: the
// first Piola stress P = F S of St. Venant-Kirchhoff, the power law or the elastoplastic law,
// fracture by element erosion). Momentum then goes through a 3D background grid with APIC
// (sim/MpmGrid.h): every step, after the Membrane's kick, the particles' new velocities (the
// lattice forces, gravity and damping already in) go to the grid and back:
// v_p <- sum_i w_ip v_i. Particles that meet in a grid cell share their nodes' velocity, so
// the grid resolves a sheet meeting itself or another piece without a contact search (and
// sticks where they touch, as MPM does).
//
// The grid's spacing is half the lattice's by default (mpm.grid). A membrane is one layer of
// particles, so the grid's in-plane nodes are what carry its motion: at h = dx there are fewer
// of them than particles (the hexagonal rows lie 0.87 dx apart), the round trip has a null
// space, and a sheet settles short of its equilibrium where the residual forces lie in it (a
// free sheet heated to 1% expansion stopped at 0.99988%). At h = dx / 2 every particle has
// nodes of its own and the statics are the lattice's exactly.
//
// Seed 002's enrichment (Sec. 5.1). That sharing is also MPM's flaw for heterogeneous
// material: particles of a stiff and a soft material in one cell average their motion.
//   * Algorithm 1, at set-up: the two ends of a lattice edge whose E, fracture energy,
//     density or yield strain factor (material maps) differ by more than kMaterialJump are boundary
//     particles. So are, as the sheet tears, the corners of every triangle a crack removed:
//     seed 002 claims MPM's advantage with topology change, and a crack is a boundary the grid
//     would otherwise glue shut.
//   * Algorithm 2, every step: the grid cells holding a boundary particle, with the cells
//     around them that share nodes with it (the quadratic stencil reaches one cell further),
//     are boundary cells. Every particle in one is enriched: it is solved on its own particle
//     domain (its velocity from its domain's forces, the Lagrangian update of eq. 23) and takes
//     no part in the grid transfer. All others are ordinary and go through the grid.
// Prescribed particles (pins and grips) keep their velocities and stay off the grid.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "sim/Lattice.h"
#include "sim/MaterialMap.h"
#include "sim/MpmGrid.h"
#include "sim/Solver.h"

namespace rend::sim {

class Mpm final : public Solver {
public:
    /// Two ends whose factors differ by more than this fraction stand on a material boundary.
    static constexpr double kMaterialJump = 0.05;

    /// domainForces: the lattice's forces (a FemCst); gridSpacing: the grid's h [m]; enrich:
    /// seed 002's enrichment (false: every free particle goes through the grid, plain MPM).
    Mpm(std::unique_ptr<Solver> domainForces, const Lattice& lattice, double gridSpacing,
        std::span<const MaterialMap> maps = {}, bool enrich = true);
    /// The registry's factory: the FEM's forces, a grid of mpm.grid times the lattice's
    /// spacing.
    static std::unique_ptr<Solver> make(const SolverSetUp& s);

    std::unique_ptr<Workspace> makeWorkspace() const override { return domain_->makeWorkspace(); }
    void forces(const StepState& s, Workspace& work,
                std::vector<Eigen::Vector3d>& force) const override {
        domain_->forces(s, work, force);
    }
    std::vector<double> stiffnessRowSums(int particleCount) const override {
        return domain_->stiffnessRowSums(particleCount);
    }
    double strainEnergy(const StepState& s, Workspace& work) const override {
        return domain_->strainEnergy(s, work);
    }
    void fracture(const StepState& s, Workspace& work) override { domain_->fracture(s, work); }
    void advance(const StepState& s, Workspace& work,
                 std::vector<Eigen::Vector3d>& force) override {
        domain_->advance(s, work, force);
    }
    double stiffening() const override { return domain_->stiffening(); }
    void reportStrength(DamageState& damage) const override { domain_->reportStrength(damage); }
    void cut(const std::vector<std::array<int, 2>>& edges) override { domain_->cut(edges); }
    /// The domain forces' history and the particles' affine velocities C_p.
    void saveState(StateWriter& out) const override;
    void loadState(StateReader& in) override;

    bool carriesMomentum() const override { return true; }
    /// Algorithm 2, then the APIC round trip of the ordinary particles.
    void transferMomentum(const TransferState& s, std::span<Eigen::Vector3d> v) override;

    /// Particles on a material boundary or a crack, as of the last transfer.
    const std::vector<std::uint8_t>& boundaryParticles() const { return boundary_; }
    /// Particles the last transfer solved on their own domains (enriched or prescribed).
    int enrichedCount() const { return enriched_; }
    const MpmGrid& grid() const { return grid_; }
    const std::vector<Eigen::Matrix3d>& affine() const { return affine_; }

private:
    void onBind() override { domain_->bind(*sharedBonds_, *damage_); }
    /// Algorithm 1 for the material maps' boundaries.
    void findMaterialBoundaries(std::span<const MaterialMap> maps);
    /// The crack's boundary particles, when something broke since the last look.
    void updateCrackBoundaries();
    /// onGrid_: free particles outside the boundary cells.
    void classify(const TransferState& s);

    std::unique_ptr<Solver> domain_;
    std::vector<Eigen::Vector3d> restPositions_;
    std::vector<std::array<int, 3>> triangles_;
    std::vector<std::array<int, 2>> edges_;       ///< the rest lattice's sides
    std::vector<std::uint8_t> materialBoundary_;  ///< Algorithm 1, fixed
    std::vector<std::uint8_t> boundary_;          ///< material and crack boundaries
    std::size_t damageSeen_ = 0;                  ///< breaks counted at the last look
    std::vector<std::uint8_t> onGrid_;
    std::vector<Eigen::Matrix3d> affine_;  ///< APIC's C_p per particle
    int enriched_ = 0;
    bool enrich_ = true;
    MpmGrid grid_;
};

}  // namespace rend::sim
