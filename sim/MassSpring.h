#pragma once
// Mass-spring membranes of the mass-spring paper (seeds/003): one spring on every edge of the
// rest lattice's triangles, f = k (|r| - L0) along the current edge.
//
//  - Van Gelder (eq. 1): k_c = sum over the edge's triangles of
//        E t / (1 + nu) |T| / c^2 + E t nu / (1 - nu^2) (a^2 + b^2 - c^2) / (8 |T|),
//    fixed at set-up. Exact for nu = 1/3 on equilateral triangles (it is then Lloyd's
//    sqrt(3)/4 E t per triangle, eq. 3); a central spring network cannot carry another nu.
//  - Two-parameter, TP-MSS (eqs. 10-17): k_b = sum_i Q_i q_i, with the fixed part
//    Q_i = E t / (8 (1 - nu^2) |T0_i|) (eq. 12) and the variable part
//    q_i = (a0^2 q_a - b0^2 q_b + c0^2 q_c) / eps_b (eq. 14), q_s = eps_n,s + nu eps_t,s (eq. 9):
//    eps_t,s the side's strain, eps_n,s the strain of the triangle's height onto side s. The
//    spring force k_b (b - b0) = k_b eps_b b0 makes eps_b cancel:
//        F_b = b0 sum_i Q_i (a0^2 q_a - b0^2 q_b + c0^2 q_c),
//    which is what we evaluate, so the division by zero that eq. 16 guards against never
//    arises. Eq. 16's k (zero strain) gives the stiffness for the stable time step.

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <vector>

#include "sim/BondLaw.h"
#include "sim/Lattice.h"
#include "sim/Solver.h"

namespace rend::sim {

enum class SpringModel { VanGelder, TwoParameter };

class MassSpring final : public Solver {
public:
    /// criticalStrain: a spring breaks once stretched past it (infinity: never). Van Gelder's
    /// springs also take the material's bond law (its shape, scaled to slope k at rest), its
    /// thermal strain alpha theta_bar and its stiffness and strength losses, as the bonds do.
    MassSpring(const Lattice& lattice, SpringModel model, const MaterialParams& material,
               double thickness, double criticalStrain);

    void forces(const std::vector<Eigen::Vector3d>& x,
                std::vector<Eigen::Vector3d>& force) const override;
    std::vector<double> stiffnessRowSums(int particleCount) const override;
    double strainEnergy(const std::vector<Eigen::Vector3d>& x) const override;
    std::vector<std::array<int, 2>> fracture(const std::vector<Eigen::Vector3d>& x) override;
    bool cut(const std::vector<std::array<int, 2>>& edges) override;

    int springCount() const { return int(springs_.size()); }
    /// Van Gelder's k of spring s (eq. 1) [N/m].
    double vanGelderStiffness(int s) const { return springs_[s].k; }

private:
    struct Spring {
        int i, j;
        double restLength;
        double k;  ///< Van Gelder (eq. 1); eq. 16's zero-strain k for the two-parameter model
    };
    struct Triangle {
        std::array<int, 3> v;
        std::array<int, 3> side;  ///< spring index of side s = the edge opposite vertex s
        std::array<double, 3> restLength;
        double restArea;
        double fixedPart;  ///< Q (eq. 12)
    };
    /// Tension of every spring [N] at x.
    void tensions(const std::vector<Eigen::Vector3d>& x) const;

    /// A broken spring carries nothing; a two-parameter triangle with a broken side carries
    /// nothing either (its sides' forces are coupled through its shape).
    void breakSpring(int s);

    /// Mechanical strain of spring s at x (thermal strain removed) and its theta_bar.
    double mechanicalStrain(int s, const std::vector<Eigen::Vector3d>& x, double& thetaBar) const;

    SpringModel model_;
    double poisson_;
    BondLaw law_;  ///< the material's law with c = 1: tension = k L0 f(eta)
    double expansion_ = 0.0, stiffnessLoss_ = 0.0, strengthLoss_ = 0.0;
    std::vector<PlasticState> plastic_;  ///< per spring; empty unless elastoplastic
    double criticalStrain_;
    std::vector<std::uint8_t> springAlive_, triangleIntact_;
    std::vector<std::array<int, 2>> springTriangles_;  ///< the (one or two) triangles of a spring
    std::vector<Spring> springs_;
    std::vector<Triangle> triangles_;
    // Per particle, its springs (signed: +s+1 when it is end i, -(s+1) when end j), so each
    // particle sums its own forces.
    std::vector<int> springOffsets_, particleSprings_;
    mutable std::vector<double> tension_;
    mutable std::vector<std::array<double, 3>> triangleTension_;
};

}  // namespace rend::sim
