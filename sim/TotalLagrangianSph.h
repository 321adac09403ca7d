#pragma once
// Kernel-corrected total-Lagrangian SPH membrane: the SPH comparison of the membrane paper
// (seeds/000, Sec. 6.1, Figs. 9-10), with the continuum law of the FEM solver so the two differ
// only in how they discretise the deformation gradient.
//
// Each particle i keeps its rest neighbours j within 2 dx and weights w_ij = V_j phi(r_ij)
// (X_j - X_i), phi a Wendland C2 kernel. The corrected gradients g_ij = A_i^-T w_ij, with
// A_i = sum_j (X_j - X_i) w_ij^T, make the deformation gradient
//     F_i = sum_j (x_j - x_i) g_ij^T                                        (3x2)
// exact for every affine motion, at free edges too. The stored energy is
// U = sum_i V_i h Psi(F_i) with Psi of St. Venant-Kirchhoff on the Green strain (plane stress),
// and the forces are its exact negative gradient:
//     f_k = V_k h P_k sum_j g_kj - sum_i V_i h P_i g_ik,   P = F S,
// so momentum and energy are conserved and rigid motions give no force. Flat rest sheets only.
//
// Notches remove the neighbour pairs that cross them, and both ends correct their gradients over
// the pairs left. The thermal strain and the theta losses apply per particle, as in the FEM.
//
// Fracture (damage-weighted pairs, after the pseudo-spring SPH of Chakraborty & Shaw 2013). A
// pair breaks for good when its rest direction d, stretched by the mean of its ends' mechanical
// F, |F_bar d| - 1, passes the critical strain of sphCriticalStrain() (weakened by theta), or
// when the pair itself is longer than kTetherStretch rest lengths. A broken pair loses its
// gradient, but the particle keeps its rest correction A_i^-T: re-correcting over the pairs
// left (tried first) gives the crack's lopsided neighbourhoods ill-conditioned gradients that
// amplify noise, and crack_path_sources shattered (4,261 broken pairs against the bonds' 511).
// Instead the particle measures strain against its rest metric C0 = B^T B, with B = sum over living
// pairs of d_ij g_ij^T: E = (F^T F - C0) / 2, so the rest state and rigid motions stay stress-free,
// the stiffness across the crack fades with the pairs, no gradient grows, and a particle with no
// pair left carries no stress. Forces stay the exact gradient. Pairs that are rest-lattice edges
// break their edge in the DamageState, which drops the triangles on either side.
//
// Why F and not the pair's own length: in crack_path_sources at dx = 0.04 (no fracture, 0.4 s)
// the longest pair stretch next to the grips is 0.051 and 0.043 inside (FEM: 0.039 and 0.019),
// the particle-scale zero-energy noise that F does not feel; seen through F the SPH gives 0.028
// and 0.019, as the FEM does. Breaking by pair length (with the
// rest metric) still tore both grips off: 3,043 broken lattice edges at 5 s. As built, the crack
// runs from the notch and bends at the source, then branches towards the right-hand corners
// (944 edges at 5 s; bonds 511, FEM 279) with nothing broken at the grips.

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "sim/Bonds.h"
#include "sim/Lattice.h"
#include "sim/Material.h"
#include "sim/Params.h"
#include "sim/Solver.h"

namespace rend::sim {

/// The pair strain at which a pair breaks, for fracture energy G_f [J/m^2]: the pairs crossing a
/// straight crack hold G = kappa E h dx e^2 per unit length under a uniaxial Green strain e normal
/// to it, so e_c = sqrt(G_f / (kappa E dx)), reached by the pair normal to the crack at stretch
/// sqrt(1 + 2 e_c) - 1. kappa is measured (sph_fracture_test).
double sphCriticalStrain(double fractureEnergy, double youngsModulus, double dx);

class TotalLagrangianSph final : public Solver {
public:
    TotalLagrangianSph(const Lattice& lattice, double dx, const Material& material,
                       double thickness, std::span<const Notch> notches,
                       double criticalStrain = std::numeric_limits<double>::infinity());
    /// The registry's factory; throws std::invalid_argument for a curved (sphere) rest sheet.
    static std::unique_ptr<Solver> make(const SolverSetUp& s);

    std::unique_ptr<Workspace> makeWorkspace() const override;
    void forces(const StepState& s, Workspace& work,
                std::vector<Eigen::Vector3d>& force) const override;
    std::vector<double> stiffnessRowSums(int particleCount) const override;
    double strainEnergy(const StepState& s, Workspace& work) const override;
    /// Breaks the pairs {i, j} as fracture would (the notches' own were removed at set-up).
    void cut(const std::vector<std::array<int, 2>>& edges) override;
    void fracture(const StepState& s, Workspace& work) override;
    /// fracture() then the forces from the same deformation gradients.
    void advance(const StepState& s, Workspace& work, std::vector<Eigen::Vector3d>& force) override;

    /// Pairs broken by fracture so far (each counted once; notches not included).
    std::size_t brokenPairCount() const { return brokenPairs_; }
    /// Broken pairs, their zeroed gradients and the damaged particles' rest metrics.
    void saveState(StateWriter& out) const override {
        out(pairAlive_), out(gradient_), out(restMetric_), out(metric_), out(brokenPairs_);
    }
    void loadState(StateReader& in) override {
        in(pairAlive_), in(gradient_), in(restMetric_), in(metric_), in(brokenPairs_);
    }
    /// Whether the pair i -> j (rest neighbours) is still whole; false when not neighbours.
    bool pairAlive(int i, int j) const;

    /// F_i at positions x.
    Eigen::Matrix<double, 3, 2> deformationGradient(int i,
                                                    std::span<const Eigen::Vector3d> x) const;

private:
    Eigen::Matrix<double, 3, 2> firstPiola(int i, const Eigen::Matrix<double, 3, 2>& F) const;
    /// Green strain of particle i against its rest metric (the identity until a pair breaks).
    Eigen::Matrix2d greenStrain(int i, const Eigen::Matrix<double, 3, 2>& F) const;
    /// The forces' scratch: F_i at the last x and V_i h P_i, per particle.
    struct SphWorkspace : Workspace {
        std::vector<Eigen::Matrix<double, 3, 2>> deformation, stress;
    };
    /// F_i of every particle at s.x.
    void deformations(const StepState& s,
                      std::vector<Eigen::Matrix<double, 3, 2>>& deformation) const;
    /// Forces from the workspace's deformation gradients.
    void forcesFrom(const StepState& s, SphWorkspace& work,
                    std::vector<Eigen::Vector3d>& force) const;
    /// Drops the pair copy k's gradient; its particle goes into `touched`.
    void breakPair(int k, std::vector<int>& touched);
    /// Rest metrics of the touched particles.
    void settle(std::vector<int>& touched);
    /// The pairs along rest-lattice edges, whose breaking breaks the DamageState's edge.
    void onBind() override;
    /// Corrected gradients of particle i over its living pairs; none when they no longer span
    /// the plane (the particle has broken loose and carries no stress).
    void correctGradients(int i);
    static double thetaAt(std::span<const double> theta, int i) {
        return theta.empty() ? 0.0 : theta[i];
    }

    void applyMaterialMaps(std::span<const MaterialMap> maps);

    // CSR neighbours of each particle with their corrected gradients g_ij; `mirror[k]` is the
    // index of the pair j -> i in j's list.
    BondFamilies pairs_;                   ///< rest neighbours within 2 dx
    std::vector<std::uint8_t> pairAlive_;  ///< per pair copy: 1 whole, 0 broken
    std::vector<int> offsets_, neighbours_, mirror_;
    std::vector<Eigen::Vector3d> rest_;
    double support_ = 0.0;
    Material material_;
    double expansion_ = 0.0;
    std::vector<Eigen::Vector2d> gradient_;
    std::vector<double> volume_;
    double lambda_ = 0.0, mu_ = 0.0, thickness_ = 0.0;
    // Issue 15's material maps; empty: 1 everywhere.
    std::vector<double> stiffness_;     ///< per particle, E over the material's
    std::vector<double> pairStrength_;  ///< per pair copy, sqrt(mean G_f / mean E) of its ends
    double stiffnessOf(int i) const { return stiffness_.empty() ? 1.0 : stiffness_[i]; }

    // Fracture: a pair past the critical strain loses its gradient; the particle keeps its rest
    // correction and measures strain against its rest metric C0_i = B_i^T B_i (see the top).
    double criticalStrain_;
    std::vector<std::int32_t> restMetric_;  ///< index into metric_ per particle, -1 undamaged
    std::vector<Eigen::Matrix2d> metric_;   ///< C0 of the damaged particles
    std::vector<std::uint8_t> breaking_;    ///< per pair copy, set by this step's check
    std::vector<int> pairEdge_;  ///< per pair copy: the DamageState's edge along it, or -1
    std::size_t brokenPairs_ = 0;
};

}  // namespace rend::sim
