#pragma once
// Constant-strain triangle (CST) membrane: the continuum reference of the seminar report
// (seeds/001) on the rest lattice's triangles. Per triangle, with rest edge matrix Dm (2x2, in
// the rest triangle's own plane, first axis along edge 01) and current edge matrix Ds (3x2):
//     F = Ds Dm^-1 (3x2),  E = (F^T F - I) / 2  (Green strain, report eq. 2.6),
//     S = lambda* tr(E) I + 2 mu E  (Hooke's law on the Green strain: St. Venant-Kirchhoff),
// with the plane-stress constants lambda* = E nu / (1 - nu^2), mu = E / (2 (1 + nu)), so nu is
// free (the bond-based model fixes 1/3). The nodal forces are the exact negative gradient of
// the stored energy A0 h (lambda*/2 tr(E)^2 + mu E:E): H = -A0 h F S Dm^-T gives vertices 1 and
// 2 as its columns, vertex 0 minus their sum.
//
// The membrane paper's other two bond laws (seeds/000, eqs. 19 and 20; sim/BondLaw.h) act on
// the principal stretches l_k of C = F^T F = V diag(l_k^2) V^T through the Biot strains
// e_k = l_k - 1, the strain the bonds and springs use. Both keep the linearisation of the
// St. Venant-Kirchhoff element (same E, nu and rest stiffness), and under uniaxial stress both
// give the nominal stress E f(e)/c of a bond, exactly:
//   * Power law (eq. 19), hyperelastic: with Phi = Psi/c the bond energy at unit stiffness and
//     q(e) = sign(e) sqrt(2 Phi(e)) (= e + O(e^2)), W = 1/2 q^T D q, D the plane-stress Hooke
//     matrix on (q_1, q_2). Uniaxial stress (dW/dq_2 = 0) leaves dW/de_1 = E q q' = E Phi' =
//     E f/c; equal biaxial strain gives E/(1-nu) f/c, as a bond family does. (The sum
//     Phi(e_1) + Phi(e_2) + nu phi(e_1) phi(e_2) would miss the uniaxial curve by O(nu^2).)
//   * Elastoplastic (eq. 20), Rankine-type softening plasticity: a plastic Biot strain Ep (2x2,
//     rest frame) and the largest equivalent strain T per element; elastic strain
//     Ee = (U - I) - Ep, U = sqrt(C), and Hooke's law T_B = lambda* tr(Ee) I + 2 mu Ee on it.
//     The history step takes the largest principal value e1 of Ee (direction n1): the total
//     strain along n1 is e1 + kappa(T), kappa(T) = T - f(T)/c the plastic strain of the bond
//     law; past max(T, eta0) the element loads: T = e1 + kappa, Ep += dkappa n1 n1^T. Under
//     uniaxial stress this is the bond's loading, softening and elastic unloading to the
//     permanent strain kappa(T), exactly; the strength left f(T)/(c eta0) is eq. 27's gamma.
// Both stresses are Biot stresses T_B (conjugate to U); with U dU + dU U = dC the second
// Piola stress is S = V [2 T_B,ij / (l_i + l_j)] V^T in U's eigenbasis (T_k / l_k on the
// diagonal), well defined when l_1 = l_2. Forces are the exact negative gradient of the energy
// (at fixed plastic history).

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <array>
#include <memory>
#include <span>
#include <vector>

#include "sim/BondLaw.h"
#include "sim/Lattice.h"
#include "sim/Material.h"
#include "sim/Params.h"
#include "sim/Solver.h"

namespace rend::sim {

class FemCst final : public Solver {
public:
    /// criticalStrain: an element is removed once its largest principal stretch exceeds
    /// 1 + criticalStrain (infinity: never).
    /// The material's thermal strain alpha theta and its stiffness and strength losses apply
    /// per element, with theta averaged over its corners.
    FemCst(const Lattice& lattice, const Material& material, double thickness,
           double criticalStrain);
    /// The registry's factory: breaks at bandCriticalStrain().
    static std::unique_ptr<Solver> make(const SolverSetUp& s);

    std::unique_ptr<Workspace> makeWorkspace() const override;
    /// With s.v (and the power law), also the smallest principal Biot strain looked ahead by
    /// s.dt at its current rate, into the workspace, for advance().
    void forces(const StepState& s, Workspace& work,
                std::vector<Eigen::Vector3d>& force) const override;
    std::vector<double> stiffnessRowSums(int particleCount) const override;
    double strainEnergy(const StepState& s, Workspace& work) const override;
    /// Yields the elastoplastic elements (their history step), then erodes those past the
    /// critical strain, in index order.
    void fracture(const StepState& s, Workspace& work) override;
    /// fracture(), forces(), and for the power law the stiffening of the most compressed
    /// principal stretch, looked ahead by dt at its current rate.
    void advance(const StepState& s, Workspace& work, std::vector<Eigen::Vector3d>& force) override;
    double stiffening() const override { return stiffening_; }
    void saveState(StateWriter& out) const override {
        out(plasticStrain_), out(maxStrain_), out(stiffening_);
    }
    void loadState(StateReader& in) override {
        in(plasticStrain_), in(maxStrain_), in(stiffening_);
    }
    /// A bond along an element side: the mean gamma of the living elements holding it; any
    /// other bond: the mean of its two ends' (each the mean over its living elements).
    void reportStrength(DamageState& damage) const override;
    /// A notch removes every element with a cut side (a gap one element wide).
    void cut(const std::vector<std::array<int, 2>>& edges) override;

    /// Green strain of triangle t at positions x, in its rest frame (first axis along edge 01).
    Eigen::Matrix2d greenStrain(int t, std::span<const Eigen::Vector3d> x) const;
    int elementCount() const { return int(elements_.size()); }
    /// Largest equivalent strain T the element reached (elastoplastic law; 0 otherwise).
    double maxStrain(int t) const { return maxStrain_.empty() ? 0.0 : maxStrain_[t]; }
    /// eq. 27's gamma of element t: 1 unless it has yielded and softened.
    double strengthLeft(int t) const;

private:
    struct Element {
        std::array<int, 3> v;
        Eigen::Matrix2d restInverse;  ///< Dm^-1
        double restArea;              ///< A0
        int triangle;                 ///< index into the lattice's triangles
        std::array<int, 3> across;    ///< element across side s (opposite vertex s), or -1
        double stiffness = 1.0;       ///< E over the material's: its corners' mean (maps)
        double strength = 1.0;        ///< the critical strain's factor, sqrt(G_f / E) (maps)
        double yield = 1.0;          ///< eta0 over the law's: its corners' mean (yield_strain maps)
        double softening = 1.0;      ///< beta over the law's: its corners' mean (softening maps)
        double powerRatio = 1.0;     ///< c*/c over the law's (power_ratio maps)
        double powerExponent = 1.0;  ///< n over the law's (power_exponent maps)
    };
    void findNeighbours();
    /// Issue 15's material maps: each element's E and critical strain from its corners'.
    void applyMaterialMaps(std::span<const MaterialMap> maps,
                           std::span<const Eigen::Vector3d> rest);
    /// Mean theta over the element's corners (0 without diffusion).
    static double thetaOf(const Element& e, std::span<const double> theta);
    /// Removes element t's triangle from the DamageState, and with `breakSides` breaks the
    /// sides no living element holds any more.
    void erode(int t, bool breakSides);
    bool elementAlive(int t) const { return damage_->triangleAlive()[elements_[t].triangle]; }
    /// eq. 27's gamma of bond b from i to j (see reportStrength()).
    double bondStrength(int b, int i, int j) const;
    Eigen::Matrix<double, 3, 2> deformationGradient(const Element& e,
                                                    std::span<const Eigen::Vector3d> x) const;
    /// Power law and elastoplastic: the second Piola stress S of element t at the mechanical
    /// deformation F (thermal stretch removed), before the stiffness loss; energy density into
    /// `energy` when asked.
    /// With `lowest`, also lowers it to the smallest principal Biot strain, looked ahead by dt
    /// at the rate dF/dt = `rate` (when given).
    /// Principal directions V of C = F^T F (columns, largest first), stretches l_k and Biot
    /// strains e_k = l_k - 1.
    struct Stretches {
        Eigen::Matrix2d directions;
        Eigen::Vector2d stretch, strain;
    };
    static Stretches stretchesOf(const Eigen::Matrix<double, 3, 2>& F);
    Eigen::Matrix2d nonlinearStress(int t, const Eigen::Matrix<double, 3, 2>& F,
                                    const Stretches& principal, double* energy,
                                    const Eigen::Matrix<double, 3, 2>* rate = nullptr,
                                    double dt = 0.0, double* lowest = nullptr) const;
    /// The forces' scratch: per element corner (element * 3 + corner) its force, and the
    /// smallest principal Biot strain looked ahead (0 when none is compressed).
    struct FemWorkspace : Workspace {
        std::vector<Eigen::Vector3d> cornerForce;
        double lowest = 0.0;
    };
    /// Elastoplastic history step of element t at the mechanical deformation F.
    void yieldElement(int t, const Stretches& principal);
    /// Whether element t is past the critical strain at x: its largest principal Green strain
    /// of the mechanical part against the critical stretch's, both weakened by theta.
    bool pastCriticalStrain(int t, std::span<const Eigen::Vector3d> x,
                            std::span<const double> theta) const;
    /// Removes the flagged elements in index order (so the sides broken do not depend on
    /// the thread count) and clears the flags; see erode() for `breakSides`.
    void erodeFlagged(bool breakSides);

    /// Element t's law: the material's, with its own beta, c*/c and n where maps set them.
    BondLaw lawOf(int t) const {
        const Element& e = elements_[t];
        return law_.scaled(e.softening, e.powerRatio, e.powerExponent);
    }
    bool ownPowerLaws_ = false;  ///< whether power-law maps gave elements laws of their own

    /// The power law's largest tangent over c among the elements at a principal strain.
    double stiffestAt(double strain) const;

    std::vector<Element> elements_;
    // Gather layout: the corners each particle belongs to (element * 3 + corner), so each
    // particle sums its own forces and the loop needs no atomics (and no ordering by thread).
    std::vector<int> cornerOffsets_, corners_;
    Material material_;
    double lambda_ = 0.0, mu_ = 0.0;  ///< the material's plane-stress Lame constants
    double thickness_ = 0.0, criticalStrain_ = 0.0, expansion_ = 0.0;
    BondLaw law_;  ///< the material's law at unit stiffness (c = 1): its shape f/c
    // Elastoplastic history per element: plastic Biot strain (rest frame) and T.
    std::vector<Eigen::Matrix2d> plasticStrain_;
    std::vector<double> maxStrain_;
    double stiffening_ = 1.0;
    std::vector<std::uint8_t> eroding_;  ///< per element: past the critical strain this step
    std::vector<int> elementOf_;         ///< per lattice triangle, its element or -1 (degenerate)
};

/// Per particle, the corners (element * 3 + corner) of the triangles that contain it, in CSR.
void triangleIncidence(const std::vector<std::array<int, 3>>& triangles, int particleCount,
                       std::vector<int>& offsets, std::vector<int>& corners);

}  // namespace rend::sim
