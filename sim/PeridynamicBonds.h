#pragma once
// The micro-spring bonds of the membrane paper (seeds/000_68a9cbaeb8170387.txt, Sections 4-5) as
// a Solver: every pair within the horizon R is a bond with one of the three laws (eqs. 18-20),
// broken for good past the critical stretch (eqs. 27-28), strained and weakened by the
// diffusing theta. The bonds are the Membrane's own BondFamilies (diffusion and the FrameView
// read them too); the force loop proposes the bonds past their limit to the DamageState, which
// breaks them after the loop (sim/DamageState.h).
//
// The force loop is compiled once per law and per whether theta exists and bonds can break,
// so a stage a scene does not need costs nothing per bond; advance() fuses fracture, yield and
// the power law's look-ahead into it.

#include <Eigen/Core>
#include <span>
#include <vector>

#include "sim/BondLaw.h"
#include "sim/Bonds.h"
#include "sim/Lattice.h"
#include "sim/Params.h"
#include "sim/Solver.h"

namespace rend::sim {

class PeridynamicBonds final : public Solver {
public:
    /// `bonds` is the Membrane's (kept by reference), `rest` and `volumes` its rest positions
    /// and particle volumes. Bind it (Solver::bind) to a DamageState over the same bonds before
    /// use.
    PeridynamicBonds(const MembraneParams& params, const Lattice& lattice,
                     const BondFamilies& bonds, std::span<const Eigen::Vector3d> rest,
                     std::span<const double> volumes);

    void forces(const std::vector<Eigen::Vector3d>& x,
                std::vector<Eigen::Vector3d>& force) const override;
    void advance(const std::vector<Eigen::Vector3d>& x, const std::vector<Eigen::Vector3d>& v,
                 double dt, std::vector<Eigen::Vector3d>& force) override;
    std::vector<double> stiffnessRowSums(int particleCount) const override;
    double strainEnergy(const std::vector<Eigen::Vector3d>& x) const override;
    double stiffening() const override { return stiffening_; }
    void reportStrength(DamageState& damage) const override;

    const BondLaw& law() const { return law_; }
    /// eta_c at theta = 0; +infinity when the material has no fracture energy.
    double criticalStretch() const { return criticalStretch_; }
    /// Virial (Cauchy-like) stress of particle i at x: 1/(2 V_i) sum_j F_ij (x) r_ij.
    Eigen::Matrix3d particleStress(int i, const std::vector<Eigen::Vector3d>& x) const;

private:
    void computeBondScales(const MembraneParams& params, double particleArea);
    void applySurfaceCorrection();
    void setUpFracture(const MaterialParams& m);
    /// The force loop for the scene's law; kUpdateBonds breaks and yields bonds on the way.
    template <bool kUpdateBonds>
    void bondForces(const std::vector<Eigen::Vector3d>& x, std::vector<Eigen::Vector3d>& force);
    template <bool kUpdateBonds, BondLawKind kLaw, bool kTheta, bool kBreak>
    void bondForcesFor(const std::vector<Eigen::Vector3d>& x, std::vector<Eigen::Vector3d>& force);
    /// Mechanical strain of bond b of particle i (diffusion strain removed) and its theta_bar.
    double mechanicalStrain(int i, int b, double length, double& thetaBar) const;
    double degradation(double loss, double thetaBar) const {
        return std::max(0.0, 1.0 - loss * thetaBar);
    }

    const BondFamilies& bonds_;
    std::span<const Eigen::Vector3d> rest_;
    std::span<const double> volume_;
    MaterialParams material_;
    double horizon_ = 0.0;
    BondLaw law_;
    double criticalStretch_ = 0.0;
    std::vector<double> bondScale_;      ///< force on i per unit of f(eta), see BondLaw.h
    std::vector<PlasticState> plastic_;  ///< per bond; empty unless the law is elastoplastic
    // The power law's look-ahead (advance() only): velocities and step, and the stiffening of
    // the most compressed bond over c.
    const std::vector<Eigen::Vector3d>* velocities_ = nullptr;
    double dt_ = 0.0;
    double stiffening_ = 1.0;
};

}  // namespace rend::sim
