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
// There is no fracture: breaking pairs by a critical strain (tried) leaves particles with
// lopsided neighbourhoods whose corrected gradients amplify noise, and the crack_path scene
// shattered along both grips (4,261 pairs against the bonds' 511), so the SPH refuses it.

#include <span>
#include <vector>

#include "sim/Bonds.h"
#include "sim/Lattice.h"
#include "sim/Params.h"
#include "sim/Solver.h"

namespace rend::sim {

class TotalLagrangianSph final : public Solver {
public:
    TotalLagrangianSph(const Lattice& lattice, double dx, const MaterialParams& material,
                       double thickness, std::span<const Notch> notches);

    void forces(const std::vector<Eigen::Vector3d>& x,
                std::vector<Eigen::Vector3d>& force) const override;
    std::vector<double> stiffnessRowSums(int particleCount) const override;
    double strainEnergy(const std::vector<Eigen::Vector3d>& x) const override;
    bool cut(const std::vector<std::array<int, 2>>&) override { return true; }  // done at set-up

    /// F_i at positions x.
    Eigen::Matrix<double, 3, 2> deformationGradient(int i,
                                                    const std::vector<Eigen::Vector3d>& x) const;

private:
    Eigen::Matrix<double, 3, 2> firstPiola(const Eigen::Matrix<double, 3, 2>& F) const;
    /// Corrected gradients of particle i over its living pairs; none when they no longer span
    /// the plane (the particle has broken loose and carries no stress).
    void correctGradients(int i);
    double thetaAt(int i) const { return theta_.empty() ? 0.0 : theta_[i]; }

    // CSR neighbours of each particle with their corrected gradients g_ij; `mirror[k]` is the
    // index of the pair j -> i in j's list.
    BondFamilies pairs_;  ///< rest neighbours within 2 dx, with alive flags
    std::vector<int> offsets_, neighbours_, mirror_;
    std::vector<Eigen::Vector3d> rest_;
    double support_ = 0.0;
    double expansion_ = 0.0, stiffnessLoss_ = 0.0, strengthLoss_ = 0.0;
    std::vector<Eigen::Vector2d> gradient_;
    std::vector<double> volume_;
    double lambda_ = 0.0, mu_ = 0.0, thickness_ = 0.0;
    mutable std::vector<Eigen::Matrix<double, 3, 2>> stress_;  ///< V_i h P_i per particle
};

}  // namespace rend::sim
