#pragma once
// The internal forces of one membrane discretisation. Membrane owns what every solver shares:
// the particles and their lumped masses, the rest lattice and its triangles, boundary
// conditions, gravity, damping, the follower pressure, the integrators with their stable step,
// the blow-up guard, diffusion, the DamageState and the FrameView. A Solver only turns a step's
// state into forces, and breaks through the DamageState's operations.
//
// The contract: everything a step depends on arrives in the StepState; forces() and
// strainEnergy() are const and write only their Workspace (the solver's scratch, made by
// makeWorkspace()) and the forces; advance() alone moves the solver's history on (yield,
// fracture through the DamageState). Solvers are listed, with what they support, in
// sim/SolverRegistry.h.
//
// Implemented by the peridynamic bonds of the membrane paper (PeridynamicBonds) and by the
// continuum, spring and SPH models of the other papers.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "sim/Bonds.h"
#include "sim/DamageState.h"
#include "sim/Domain.h"
#include "sim/StateArchive.h"

namespace rend::sim {

struct SolverSetUp;  // sim/SolverRegistry.h: what a solver's factory builds it from
class Contact;       // sim/Contact.h: the ground and colliders a grid's nodes collide with

/// The step's motion of a range of particles, handed to a solver's advance() (StepState::motion)
/// so that it can move each block of particles as soon as its forces are final, while they are
/// still in cache (Membrane's kick and drift and the blow-up guard's sample: at 10^6 particles
/// the separate pass read the forces, positions and velocities back from memory).
class BlockMotion {
public:
    virtual ~BlockMotion() = default;
    /// Moves particles [begin, end) by their forces. A solver that calls it calls it once for
    /// each particle it owns, from any of its threads, after which it reads none of their
    /// positions or velocities again in that advance(). `block`, where not null, holds the
    /// forces of particles [first, end) (particle i's x y z from block[3 (i - first)]), which
    /// the solver kept there rather than in advance()'s force array; else they are in it.
    virtual void move(int begin, int end, const double* block, int first) = 0;
};

struct FailureApproach;

/// One step's state, passed explicitly.
struct StepState {
    std::span<const Eigen::Vector3d> x;  ///< positions
    std::span<const Eigen::Vector3d> v;  ///< velocities; empty where only forces are asked
    std::span<const double> theta;       ///< the diffusing quantity; empty without diffusion
    double dt = 0.0;                     ///< the step about to be taken [s]
    /// stiffening() need be exact only above this (>= 1): a fixed step stays whole for any
    /// stiffening up to it, so a solver may report it for anything less (Membrane::piecesOfStep).
    double stiffeningNeeded = 1.0;
    /// At least every particle's speed |v|, or < 0 where unknown (Membrane::speedBound): the
    /// power law's look-ahead then bounds its pairs' rates from it instead of reading v.
    double speedBound = -1.0;
    /// What changed since the solver's last advance() (Membrane::driftSincePass_): each
    /// particle moved only by a drift of `drift` seconds at its present velocity (so at most
    /// drift x speedBound), and theta by at most thetaChange; < 0 where unknown. positionScale
    /// is at least every |coordinate| of x.
    struct SinceLastPass {
        double drift = -1.0, thetaChange = -1.0;
        double positionScale = std::numeric_limits<double>::infinity();
    };
    SinceLastPass sinceLastPass{};
    /// Non-null: advance() may move the particles through it instead of leaving that to the
    /// caller (the caller asks the motion whether it moved them). forces() never does.
    BlockMotion* motion = nullptr;
    /// Non-null (advance() only, where the solver measuresApproachInPass() and motion is null):
    /// the pass also writes failureApproachRate(s, *approach) into *approachRate, the same bits.
    const FailureApproach* approach = nullptr;
    double* approachRate = nullptr;
};

/// What Membrane::failureApproachRate measures a step by (its constants).
struct FailureApproach {
    double criticalStretch = 0.0;  ///< the membrane's eta_c, without maps
    double expansion = 0.0, strengthLoss = 0.0;
    double maxStretchIncrement = 0.0;
};

/// What a solver that carries momentum through a grid (Solver::transferMomentum) reads.
struct TransferState {
    std::span<const Eigen::Vector3d> x;  ///< positions the velocities are about to move
    std::span<const double> mass;
    std::span<const std::uint8_t> free;  ///< per particle: 0 where pinned or driven
    double dt = 0.0;
    const Contact* contact = nullptr;  ///< the ground and colliders, placed; none: nullptr
};

/// A solver's scratch for one force evaluation (per-element or per-spring intermediates). Each
/// solver derives its own and makes it with Solver::makeWorkspace().
class Workspace {
public:
    virtual ~Workspace() = default;
};

class Solver {
public:
    virtual ~Solver() = default;

    /// The scratch forces(), strainEnergy() and advance() need; a plain Workspace by default.
    virtual std::unique_ptr<Workspace> makeWorkspace() const {
        return std::make_unique<Workspace>();
    }

    /// Internal force on every particle at s.x, overwriting `force` (resized to the particles).
    /// The sum over particles is zero: forces are internal. Changes no state.
    virtual void forces(const StepState& s, Workspace& work,
                        std::vector<Eigen::Vector3d>& force) const = 0;

    /// Per particle, half the absolute row sum of the rest stiffness matrix [N/m] (for springs,
    /// sum_j k_ij): by Gershgorin omega_max^2 <= 2 k_i / m_i, so the explicit schemes are stable
    /// for dt <= sqrt(2 m_i / k_i), the same bound as the peridynamic bonds'.
    virtual std::vector<double> stiffnessRowSums(int particleCount) const = 0;

    /// Stored elastic energy at s.x [J].
    virtual double strainEnergy(const StepState& s, Workspace& work) const = 0;

    /// Breaks, for good, whatever is past its critical strain at s.x (through the
    /// DamageState's operations), and yields whatever yields. Nothing by default.
    virtual void fracture(const StepState& s, Workspace& work) {}

    /// One step's forces at s.x that also move the solver's history on, as fracture() then
    /// forces(). A law that stiffens (the power law in compression) looks ahead by s.v and
    /// s.dt for stiffening().
    virtual void advance(const StepState& s, Workspace& work, std::vector<Eigen::Vector3d>& force) {
        fracture(s, work);
        forces(s, work, force);
    }

    /// The worst tangent stiffness over its rest value (>= 1) seen by the last advance(): the
    /// explicit step is cut into pieces so each stays within the rest bound over its square root.
    virtual double stiffening() const { return 1.0; }

    /// Writes into the DamageState, with weaken(), eq. 27's gamma of every bond whose strength
    /// the solver keeps in its own pieces (springs, elements); called once per frame, for the
    /// damage field. Nothing by default: every bond keeps full strength.
    virtual void reportStrength(DamageState& damage) const {}
    /// Membrane::failureApproachRate over this process's particles' bonds by the solver's own
    /// pair loop, where it has one: the same value, bit for bit. None by default (Membrane's
    /// loop over its bonds).
    virtual std::optional<double> failureApproachRate(const StepState& s,
                                                      const FailureApproach& f) const {
        return std::nullopt;
    }
    /// Whether advance() measures failureApproachRate in its own pass (StepState::approach) and
    /// reads neither StepState::dt nor StepState::speedBound: an adaptive step may then be
    /// chosen after the pass, from the rate that pass measured at the step's start (Membrane::
    /// advanceTo). No by default.
    virtual bool measuresApproachInPass() const { return false; }
    /// The solver's own history (plastic strains, broken pieces) for a checkpoint
    /// (sim/StateArchive.h), read back into a solver built from the same scene. Nothing by
    /// default: a solver without history keeps it all in the DamageState.
    virtual void saveState(StateWriter& out) const {}
    virtual void loadState(StateReader& in) {}

    /// Whether the solver carries momentum through a background grid (MPM): the Membrane then
    /// hands it every step's new velocities, before they move the particles.
    virtual bool carriesMomentum() const { return false; }
    /// Replaces the velocities v (after the kick, at s.x) by the grid's; see sim/Mpm.h.
    virtual void transferMomentum(const TransferState& s, std::span<Eigen::Vector3d> v) {}

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

    /// From now on computes only what slab `slab` needs (sim/Domain.h): the forces on its own
    /// particles, the updates of their bonds, and its share of the strain energy. False where
    /// the solver cannot.
    virtual bool restrictTo(const Slab& slab) { return false; }

    // Conveniences for tests and tools: one call at x (theta none) with a fresh workspace.
    std::vector<Eigen::Vector3d> forcesAt(std::span<const Eigen::Vector3d> x) const {
        std::vector<Eigen::Vector3d> force;
        forces({x, {}, {}, 0.0}, *makeWorkspace(), force);
        return force;
    }
    double energyAt(std::span<const Eigen::Vector3d> x) const {
        return strainEnergy({x, {}, {}, 0.0}, *makeWorkspace());
    }
    void fractureAt(std::span<const Eigen::Vector3d> x) {
        fracture({x, {}, {}, 0.0}, *makeWorkspace());
    }
    std::vector<Eigen::Vector3d> advanceAt(std::span<const Eigen::Vector3d> x,
                                           std::span<const Eigen::Vector3d> v, double dt) {
        std::vector<Eigen::Vector3d> force;
        advance({x, v, {}, dt}, *makeWorkspace(), force);
        return force;
    }

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
