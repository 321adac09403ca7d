#pragma once
// The peridynamic membrane of the membrane paper (seeds/000_68a9cbaeb8170387.txt, Sections
// 4.1-4.4): one layer of particles joined by micro-springs within the cutoff R, advanced with
// the explicit symplectic Euler scheme of eq. 26 (velocity first, then position).

#include <Eigen/Core>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/BondLaw.h"
#include "sim/Bonds.h"
#include "sim/FrameView.h"
#include "sim/Lattice.h"
#include "sim/Params.h"

namespace rend::sim {

/// The state stopped being finite, or a particle ran away faster than anything the material
/// or the boundary conditions can produce.
class NumericalBlowUp : public std::runtime_error {
public:
    NumericalBlowUp(const std::string& message, long step, int particle, double suggestedDt)
        : std::runtime_error(message), step(step), particle(particle), suggestedDt(suggestedDt) {}
    long step;
    int particle;
    double suggestedDt;
};

class Membrane {
public:
    explicit Membrane(const MembraneParams& params);

    /// Below this many particles a step takes microseconds and waking the OpenMP team costs more
    /// than it saves; the loop body is the same either way, so results do not change.
    static constexpr int kParallelThreshold = 2048;

    int particleCount() const { return int(x0_.size()); }
    std::size_t bondCount() const { return bonds_.bondCount(); }
    double horizon() const { return horizon_; }
    double micromodulus() const { return law_.c; }

    /// Silling & Askari (2005) bound for the explicit scheme, without safety factor:
    /// dt <= min_i sqrt(2 m_i / sum_j k_ij), k_ij the bond's axial stiffness at rest. It is the
    /// Gershgorin bound on the highest frequency, so symplectic Euler is stable below it.
    double stableTimeStep() const { return stableDt_; }
    double timeStep() const { return dt_; }
    void setTimeStep(double dt) { dt_ = dt; }
    double time() const { return time_; }
    long stepCount() const { return steps_; }

    /// One explicit step: bond forces, then velocities, then positions (eq. 26). Throws
    /// NumericalBlowUp naming the step and the first offending particle.
    void step();

    /// Internal bond forces on every particle (eq. 22 with the current bond direction).
    void computeForces(std::vector<Eigen::Vector3d>& force) const;

    double kineticEnergy() const;
    double strainEnergy() const;
    double maxSpeed() const;
    std::size_t brokenBondCount() const;
    Eigen::Vector3d totalMomentum() const;
    /// Virial (Cauchy-like) stress of particle i: 1/(2 V_i) sum_j F_ij (x) r_ij.
    Eigen::Matrix3d particleStress(int i) const;
    /// Number of particles each boundary condition claims (a later one wins an overlap).
    std::vector<int> boundaryParticleCounts() const;

    FrameView view(int frame) const;

    std::vector<Eigen::Vector3d>& positions() { return x_; }
    std::vector<Eigen::Vector3d>& velocities() { return v_; }
    const std::vector<Eigen::Vector3d>& positions() const { return x_; }
    const std::vector<Eigen::Vector3d>& restPositions() const { return x0_; }
    const std::vector<double>& masses() const { return mass_; }
    const std::vector<double>& volumes() const { return volume_; }
    BondFamilies& bonds() { return bonds_; }
    const BondFamilies& bonds() const { return bonds_; }
    const Lattice& lattice() const { return lattice_; }

private:
    static constexpr std::int16_t kFree = -1;
    static constexpr std::int16_t kPinned = -2;

    void computeBondScales(const MembraneParams& params);
    void assignBoundaries();
    void perturb(double amplitude, std::uint64_t seed);
    Eigen::Vector3d boundaryVelocity(int k, double t) const;
    void integrate();
    [[noreturn]] void reportBlowUp() const;
    bool isBad(int i) const;

    MembraneParams params_;
    Lattice lattice_;
    BondFamilies bonds_;
    LinearBondLaw law_;
    double horizon_ = 0.0;
    double stableDt_ = 0.0;
    double dt_ = 0.0;
    double time_ = 0.0;
    long steps_ = 0;
    double speedLimit_ = 0.0;

    // Structure of arrays: one contiguous array per attribute.
    std::vector<Eigen::Vector3d> x_, v_, x0_, force_;
    std::vector<double> mass_, volume_;
    std::vector<std::int16_t> constraint_;  ///< kFree, kPinned or a boundary index
    std::vector<double> bondScale_;         ///< force on i per unit of f(eta), see BondLaw.h
};

}  // namespace rend::sim
