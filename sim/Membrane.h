#pragma once
// The membrane of the membrane paper (seeds/000_68a9cbaeb8170387.txt, Sections 4-5): one layer
// of particles with the bonds within the cutoff R, a diffusive quantity theta (eq. 25) moving
// along them, advanced with the explicit symplectic Euler scheme of eq. 26 (velocity first,
// then position) or velocity Verlet. The internal forces come from the scene's Solver: the
// paper's micro-spring bonds (PeridynamicBonds) or one of the other papers' discretisations.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/BlowUpGuard.h"
#include "sim/BondLaw.h"
#include "sim/Bonds.h"
#include "sim/Contact.h"
#include "sim/DamageState.h"
#include "sim/Diffusion.h"
#include "sim/Fracture.h"
#include "sim/FrameView.h"
#include "sim/Lattice.h"
#include "sim/Parallel.h"
#include "sim/Params.h"
#include "sim/ParticleLevelSet.h"
#include "sim/Random.h"
#include "sim/Remesh.h"
#include "sim/Solver.h"
#include "sim/StateArchive.h"
#include "sim/StepKernels.h"
#include "sim/TimeStep.h"

namespace rend::sim {

class Membrane {
public:
    explicit Membrane(const MembraneParams& params);

    int particleCount() const { return int(x0_.size()); }
    const MembraneParams& params() const { return params_; }
    std::size_t bondCount() const { return bonds_.bondCount(); }
    double horizon() const { return horizon_; }
    /// The scene's solver (its own constants, e.g. PeridynamicBonds::criticalStretch(), are
    /// reached by a cast).
    const Solver& solver() const { return *solver_; }
    /// This step's state as the solver sees it.
    StepState stepState() const { return {x_, v_, theta_, dt_, 1.0, speedBound_}; }
    bool hasDiffusion() const { return diffusion_.has_value(); }
    const Diffusion* diffusion() const { return diffusion_ ? &*diffusion_ : nullptr; }
    std::size_t notchedBondCount() const { return notched_; }

    /// Silling & Askari (2005) bound for the explicit scheme, without safety factor:
    /// dt <= min_i sqrt(2 m_i / sum_j k_ij), k_ij the bond's axial stiffness at rest. It is the
    /// Gershgorin bound on the highest frequency, so symplectic Euler is stable below it.
    double stableTimeStep() const { return stableDt_; }
    double timeStep() const { return dt_; }
    void setTimeStep(double dt) { dt_ = dt; }
    double time() const { return time_; }
    long stepCount() const { return steps_; }
    /// Extra pieces steps were cut into because the power law stiffened in compression.
    long extraSubsteps() const { return subSteps_; }
    /// The smallest and largest step taken so far (0 before the first).
    double smallestTimeStep() const { return steps_ > 0 ? dtMin_ : 0.0; }
    double largestTimeStep() const { return dtMax_; }
    /// The stable bound now: the rest one over the square root of the last stiffening.
    double currentStableTimeStep() const;
    /// The adaptive step's fracture measure, the same for every solver: over the intact bonds of
    /// the bond families (every pair within R) loaded past half the critical stretch and
    /// stretching, the largest (ds/dt) / max((eta_c - s) / 2, delta eta_c) [1/s], with
    /// s = |x_j - x_i| / |x0_j - x0_i| - 1 - alpha theta and delta = max_stretch_increment: one
    /// over the shortest time in which a bond closes half its way to eta_c, or delta eta_c of it.
    /// 0 when nothing breaks.
    double failureApproachRate() const;
    /// The eta_c that scales it: the continuum's calibrated sqrt(2 pi G_f / (3 E R)) (Fracture.h),
    /// infinite without a fracture energy.
    double referenceCriticalStretch() const { return criticalStretch_; }
    const TimeStepController& stepController() const { return controller_; }
    /// Ground, colliders and self-contact (sim/Contact.h); nullptr when the scene has none.
    const Contact* contact() const { return contact_ ? &*contact_ : nullptr; }
    /// Wall seconds spent in contact so far (colliders and self-contact), for the share of the
    /// step it costs.
    double contactSeconds() const { return contactSeconds_; }
    /// The longest step contact allows at the current speeds (infinite without contact).
    double contactStepLimit() const;

    /// One explicit step (eq. 26): bond forces (breaking bonds past eta_c, yielding
    /// elastoplastic ones), then velocities, then positions, then theta. Throws
    /// NumericalBlowUp naming the step and the first offending particle.
    void step();
    /// Whether a step may move the particles inside the solver's force pass (StepState::motion:
    /// the same bits, fewer trips to memory); on by default. Off: the kick and drift after the
    /// pass, as before (tests and benchmarks compare the two).
    void setKickInPass(bool on) { kickInPass_ = on; }
    /// Whether the last step's particles moved inside the force pass.
    bool keptKickInPass() const { return keptKickInPass_; }
    /// Whether advanceTo may measure a step's failure approach rate in the next step's force
    /// pass, and choose that step's length after it (the same bits, one pass over the pairs
    /// fewer); on by default. Off: a pass of its own after every step (tests, the benchmark).
    void setApproachInPass(bool on) { approachInPass_ = on; }
    /// The steps whose failure approach rate the next step's force pass measured, so far.
    long approachesInPass() const { return approachesInPass_; }
    /// The blow-up guard's energy budget so far [J]: the start's energy and the work the
    /// boundaries (|force . v| on the driven particles), gravity and the rest did since.
    double energyBudget() const { return guard_.budget(); }
    /// The free particles' kinetic energy the blow-up guard measured at its last check [J].
    double checkedKinetic() const { return guard_.checkedKinetic(); }

    /// Adaptive stepping (time.dt = "adaptive", sim/TimeStep.h): steps until time() is exactly
    /// tEnd, each step from the controller, the last ones evened out to land on tEnd.
    void advanceTo(double tEnd);
    /// At a frame's start: the self-contact's candidate list is rebuilt (Contact::expireList),
    /// so that a run resumed from a checkpoint at this frame steps on with the same bits.
    void startFrame() {
        if (contact_) contact_->expireList();
    }

    /// The evolving state, for a checkpoint (sim/StateArchive.h): read back with loadState
    /// into a membrane built from the same scene, it steps on with the same bits. Taken
    /// between frames (after startFrame's frame ends, before the next one starts). Written into
    /// `reuse`'s storage where given (a caller saving every frame keeps its pages).
    std::vector<std::byte> saveState(std::vector<std::byte> reuse = {}) const;
    /// Throws StateMismatch when `bytes` do not fit this membrane (another scene, truncated).
    void loadState(std::span<const std::byte> bytes);

    /// The solver's internal forces on every particle (for the bonds, eq. 22 with the current
    /// bond direction), without changing any state.
    void computeForces(std::vector<Eigen::Vector3d>& force) const;

    /// Recomputes the per-particle damage field: 1 - sum of intact weighted bond strength /
    /// sum of initial weights. Called once per frame, not per step.
    void updateDamage();

    double kineticEnergy() const;
    double strainEnergy() const;
    double maxSpeed() const;

    /// Steps only the slab `domain` gives this process from now on (sim/Domain.h), kept by
    /// reference. Throws std::invalid_argument naming what the scene uses that a decomposed run
    /// does not (another solver, self-contact, remeshing, ...).
    void decompose(Domain& domain);
    /// Brings every slab's particles and bonds to process 0, so that its state is the whole
    /// sheet's (the others keep theirs): between frames, before process 0 writes them.
    void gatherToFirst();
    double maxTheta() const;  ///< 0 without diffusion
    std::size_t brokenBondCount() const;
    Eigen::Vector3d totalMomentum() const;
    /// The particle whose rest position (x, y) is nearest to `at` (the lowest index on a tie).
    int nearestParticle(const Eigen::Vector2d& at) const;
    /// Number of particles each boundary condition claims (a later one wins an overlap).
    std::vector<int> boundaryParticleCounts() const;

    FrameView view(int frame) const;

    // Writable state: the caller may change it, so cached forces are recomputed next step.
    std::vector<Eigen::Vector3d>& positions() {
        forcesCurrent_ = false;
        driftSincePass_ = -1.0;
        return x_;
    }
    std::vector<Eigen::Vector3d>& velocities() {
        forcesCurrent_ = false;
        speedBound_ = -1.0;
        driftSincePass_ = -1.0;
        return v_;
    }
    const std::vector<Eigen::Vector3d>& velocities() const { return v_; }
    std::vector<double>& theta() {  ///< empty without diffusion
        forcesCurrent_ = false;
        driftSincePass_ = -1.0;
        return theta_;
    }
    const std::vector<double>& theta() const { return theta_; }
    const std::vector<double>& damage() const { return damage_; }
    /// Whether any bond can break or soften (fracture energy, elastoplastic law or notches).
    bool canDamage() const { return canDamage_; }
    const std::vector<Eigen::Vector3d>& positions() const { return x_; }
    const std::vector<Eigen::Vector3d>& restPositions() const { return x0_; }
    const std::vector<double>& masses() const { return mass_; }
    /// Every particle's mass where they are all the same to the bit (a sheet without a density
    /// map whose particles have one area), else 0: the kick and the guard then read no masses.
    double oneMass() const { return oneMass_; }
    const std::vector<double>& volumes() const { return volume_; }
    BondFamilies& bonds() { return bonds_; }
    const BondFamilies& bonds() const { return bonds_; }
    const Lattice& lattice() const { return lattice_; }
    /// Which bonds are broken and triangles removed (sim/DamageState.h).
    const DamageState& damageState() const { return damageState_; }

private:
    static constexpr std::int16_t kFree = -1;
    static constexpr std::int16_t kPinned = -2;

    /// Stable step and the blow-up guard from max_i k_i / m_i (Solver::stiffnessRowSums).
    void setStableStep(double worstRatio);
    /// Hands the internal forces to `solver` and takes its stable step.
    void useSolver(std::unique_ptr<Solver> solver);
    /// The solver's forces (updating its state) and pressure into force_; a non-null `motion`
    /// lets the solver move the particles as it goes (StepState::motion).
    /// Also measures failureApproachRate() at x^n into *approachRate where that is not null
    /// (approachInPass()).
    void accumulateForces(BlockMotion* motion = nullptr, double* approachRate = nullptr);
    FailureApproach failureApproach() const;
    /// Whether advanceTo chooses a step after its force pass, which then measures the last
    /// step's failure approach rate (Solver::measuresApproachInPass).
    bool approachInPass() const;
    /// The controller's record of the last step, with its failure approach rate.
    void recordStep(double failureRate);
    void addPressure(std::vector<Eigen::Vector3d>& force) const;
    void stepSymplecticEuler();
    void stepVelocityVerlet();
    /// v += h * acceleration for free particles; prescribed velocities for the others.
    void kick(double h, double tNext);
    void updateVelocity(int i, double h, double tNext, const Eigen::Vector3d& gravity,
                        double damping);
    /// The blow-up guard, after every step; `thetaSums`: theta's half of its sample, where the
    /// diffusion took it as it wrote theta this step (BlowUpGuard::State::thetaSums).
    void checkFinite(const GuardSums* thetaSums = nullptr);
    /// Notches: breaks the bonds they cross and has the solver cut the same edges.
    void setUpNotches(const MembraneParams& params);
    ParticleLevelSet makeLevelSet() const;
    void assignBoundaries();
    Eigen::Vector3d boundaryVelocity(int k, double t) const;
    /// Velocities then positions over h, with boundary velocities at tNext (eq. 26).
    /// `moved`: the force pass already kicked and drifted (stepSymplecticEuler), with
    /// kickAndDrift's answer; only the contact and the ghosts are left.
    void integrate(double h, double tNext, std::optional<bool> moved = std::nullopt);
    /// Whether this step's kick and drift may run inside the force pass: symplectic Euler in
    /// one piece, nothing added to the forces after the solver's, no colliders but the ground.
    bool mayKickInPass() const;
    /// The kick that goes with a drift of dt (integrate's).
    double kickBefore(double dt) const { return lastDrift_ > 0.0 ? 0.5 * (lastDrift_ + dt) : dt; }
    /// The kick of h and drift of dt with boundary velocities at tNext (held by `prescribed`).
    KickDrift kickDriftOf(double h, double dt, double tNext, std::vector<double>& prescribed);
    /// What the blow-up guard samples of the motion.
    BlowUpGuard::State motionState() const;
    /// integrate's kick of h and drift of dt over this process's particles (not the MPM's);
    /// false where the ground is the only collider and no free particle reached it.
    bool kickAndDrift(double h, double dt, double tNext);
    /// Contact after a drift to tNext: the colliders placed there push the free particles out
    /// (`mayTouch` false: the drift found that nothing touches them).
    void collide(double tNext, bool mayTouch = true);
    void setUpContact(const MembraneParams& params);
    /// Pieces to cut this step into: sqrt of the power law's stiffening, capped.
    int piecesOfStep();
    double stiffeningPieces(double stiffening) const;
    double stiffeningNeeded() const;
    std::size_t breakCount() const;
    /// Refreshes the ghosts of x and v (decomposed runs only).
    void exchangeMotion();
    /// The whole sheet's kinetic plus strain energy, from the slabs (decomposed runs).
    double totalEnergy() const;
    /// The colliders' work on the sheet since the last step, over all slabs.
    double colliderWork();
    /// The fastest particle's speed over all slabs (maxSpeed() where not decomposed).
    double slabMaxSpeed() const;
    /// saveState's and loadState's fields, in order (sim/MembraneState.cpp).
    template <class Self, class Archive>
    static void visitState(Self& m, Archive& a);

    MembraneParams params_;
    Lattice lattice_;
    BondFamilies bonds_;
    DamageState damageState_;  ///< broken bonds, removed triangles: the one owner
    bool canDamage_ = false;
    std::size_t notched_ = 0;
    std::optional<Diffusion> diffusion_;
    std::optional<Contact> contact_;
    std::vector<std::uint8_t> free_;  ///< per particle: 1 unless pinned or driven
    double contactSeconds_ = 0.0;
    double horizon_ = 0.0;
    double stableDt_ = 0.0;
    double dt_ = 0.0;
    double time_ = 0.0;
    long steps_ = 0;
    BlowUpGuard guard_;
    std::unique_ptr<Solver> solver_;            ///< the internal forces
    std::unique_ptr<Workspace> workspace_;      ///< the solver's scratch for step()
    std::optional<ParticleLevelSet> levelSet_;  ///< params.particleLevelSet, a flat sheet
    std::optional<Remesher> remesher_;          ///< remesh.every > 0
    Domain* domain_ = nullptr;  ///< decomposed runs: this process's slab and its partners
    int begin_ = 0, end_ = 0;   ///< the particles this process steps: all, or its slab
    double stiffening_ = 1.0;   ///< the solver's worst tangent stiffness over its rest one
    long subSteps_ = 0;         ///< extra pieces the power law's stiffening asked for
    double lastDrift_ = 0.0;    ///< the last symplectic Euler drift, 0 before the first
    TimeStepController controller_;
    double criticalStretch_ = std::numeric_limits<double>::infinity();
    bool adaptiveStep_ = false;  ///< step() runs inside advanceTo (the guard's advice)
    double dtMin_ = std::numeric_limits<double>::infinity(), dtMax_ = 0.0;
    static constexpr int kMaxPieces = 64;

    // Structure of arrays: one contiguous array per attribute.
    std::vector<Eigen::Vector3d> x_, v_, x0_, force_;
    std::vector<double> mass_, volume_;
    double oneMass_ = 0.0;                  ///< oneMass()
    std::vector<std::int16_t> constraint_;  ///< kFree, kPinned or a boundary index
    std::vector<double> theta_;             ///< diffusive quantity; empty without diffusion
    std::vector<double> damage_;            ///< per particle; empty unless canDamage_
    bool kickInPass_ = true, keptKickInPass_ = false;
    bool approachInPass_ = true;
    long approachesInPass_ = 0;
    /// advanceTo's last step, not yet recorded: the next step's pass measures its failure
    /// approach rate, or a pass of its own at the frame's end.
    struct UnrecordedStep {
        double taken = 0.0;
        std::size_t broken = 0;
    };
    std::optional<UnrecordedStep> unrecorded_;
    /// advanceTo's choice of the step's length, made after the force pass (approachInPass()).
    const std::function<void()>* chooseAfterForces_ = nullptr;
    bool forcesCurrent_ = false;  ///< force_ holds the forces of the current x (Verlet reuses them)
    /// At least every particle's |v| since the last check (StepState::speedBound), or -1 once v
    /// may have changed: the guard's largest free speed, and the boundaries' speeds.
    double speedBound_ = -1.0;
    /// StepState::SinceLastPass::drift: the drift of the last step where the solver's pass
    /// came before it and nothing but the drift moved the particles since (a whole step of
    /// symplectic Euler, no collider touched, not decomposed), else -1.
    double driftSincePass_ = -1.0;
    bool collided_ = false;  ///< the last collide() may have moved particles
    double extent_ = 0.0;    ///< the largest |coordinate| of x at set-up
};

}  // namespace rend::sim
