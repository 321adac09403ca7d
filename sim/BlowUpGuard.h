#pragma once
// The blow-up guard: after every step, stops a run whose state is not finite or whose motion
// grows faster than anything the scene drives it with.
//
// An explicit step above the stability bound amplifies the highest lattice mode by a fixed
// factor per step (|lambda| > 1 with lambda + 1/lambda = 2 - (omega dt)^2), so the kinetic
// energy of the free particles grows geometrically. Legitimate motion gets its energy from the
// start state, the velocity boundaries, gravity, the pressure or the diffusive quantity's
// expansion; the guard keeps an upper bound on that energy (the budget) and trips when the
// kinetic energy has grown by kGrowth per step for kGrowthSteps steps in a row and exceeds
// kBudgetFactor times the budget, or exceeds kRunawayFactor times it however it grew. A speed
// beyond any plausible one, or a value that is not finite, trips it at once.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/Domain.h"
#include "sim/Params.h"
#include "sim/StepKernels.h"

namespace rend::sim {

/// The state stopped being finite, or it grew faster than the scene can drive it.
class NumericalBlowUp : public std::runtime_error {
public:
    NumericalBlowUp(const std::string& message, long step, int particle, double suggestedDt)
        : std::runtime_error(message), step(step), particle(particle), suggestedDt(suggestedDt) {}
    long step;
    int particle;
    double suggestedDt;
};

/// The dt a blow-up message suggests: half the smaller of the step and the stable bound, or 0
/// when that is not a positive finite number (the message then gives no number).
double suggestedTimeStep(double dt, double stableDt);

class BlowUpGuard {
public:
    static constexpr double kGrowth = 1.4;        ///< kinetic energy ratio per step
    static constexpr int kGrowthSteps = 3;        ///< steps in a row that grow by kGrowth
    static constexpr double kBudgetFactor = 4.0;  ///< kinetic energy over the budget
    /// Kinetic energy over the budget that trips the guard however slowly it grew: a step just
    /// above a solver's true bound, or a solver that creates energy, can grow by less than
    /// kGrowth per step. Far above what the
    /// shipped scenes reach with any solver (README "Blow-up guard").
    static constexpr double kRunawayFactor = 10.0;
    static constexpr double kLightSpeed = 2.998e8;  ///< no speed limit exceeds it [m/s]

    BlowUpGuard() = default;
    /// `worstRatio` is max_i k_i / m_i of the solver (Membrane::setStableStep).
    BlowUpGuard(const MembraneParams& params, double worstRatio, std::span<const double> mass,
                std::span<const double> volume);

    /// Per-particle speed no run can reach: far above the fastest wave, the boundaries and free
    /// fall over the whole run, finite whatever the scene says.
    double speedLimit() const { return speedLimit_; }

    /// What one step left; constraint is -1 for a free particle, -2 for a pinned one and the
    /// boundary's index (>= 0) for a driven one, as Membrane stores it.
    struct State {
        std::span<const Eigen::Vector3d> x, v, force, restPositions;
        std::span<const double> mass, theta;
        std::span<const std::int16_t> constraint;
        long step = 0;
        double time = 0.0, dt = 0.0, stableDt = 0.0;
        bool adaptive = false;      ///< the step came from the adaptive controller (sim/TimeStep.h)
        double colliderWork = 0.0;  ///< at most what moving colliders did on the sheet [J]
        /// Decomposed (sim/Domain.h): this process samples its slab, and the sums are reduced
        /// over all of them, so every process decides alike.
        Domain* domain = nullptr;
        double oneMass = 0.0;  ///< > 0: every particle's mass (sim/StepKernels.h's GuardInput)
        /// theta's half of the sample (guardThetaSums over the particles sampled), where the
        /// diffusion took it as it wrote theta (Diffusion::thetaSums): theta is then not read
        /// again for it. Null: read.
        const GuardSums* thetaSums = nullptr;
    };
    /// Checks the state after a step; throws NumericalBlowUp naming the step, the fastest (or
    /// first non-finite) particle and a suggested dt. `totalEnergy` (kinetic + strain) is
    /// called once, on the first check, to start the budget.
    void check(const State& state, const std::function<double()>& totalEnergy);

    double budget() const { return budget_; }
    /// The free particles' kinetic energy at the last check (over every process) [J].
    double checkedKinetic() const { return lastKinetic_; }
    /// The largest free particle's |v|^2 at the last check (over every process), or < 0 before
    /// the first.
    double checkedSpeedSquared() const { return checkedSpeedSquared_; }

    /// Sums of one pass over the particles (in fixed blocks, so any thread count gives the
    /// same bits).
    struct Sample {
        double kinetic = 0.0;          ///< of the free particles [J]
        double boundaryPower = 0.0;    ///< |force . v| on the driven particles [W]
        double gravityPower = 0.0;     ///< |m g . v| on the free particles [W]
        double maxSpeedSquared = 0.0;  ///< of the free particles
        double maxAbsTheta = 0.0;
        int fastest = -1;   ///< lowest index at the highest speed
        int firstBad = -1;  ///< lowest index whose x, v or theta is not finite or too fast
    };
    Sample sample(const State& state) const;

    /// Particles per block of a sample: fixed, so that its sums do not depend on the threads.
    /// A solver's pass moves PeridynamicBonds::kFusedBlock particles at a time: as many, so
    /// that the kick in the pass takes a block's sums in its own loop.
    static constexpr int kBlock = 512;
    /// The motion half of the next check's sample (all but theta), block by block, taken by the
    /// integrator right after it moved each block, while the block is in cache: the bits
    /// check() would take. beginMotion() over the particles [first, last) a check samples,
    /// sampleMotion() for each of their blocks (from any thread), endMotion(). Until the next
    /// check, v, force, mass and constraint must not change, or forgetMotion() must be called.
    void beginMotion(int first, int last);
    void sampleMotion(const State& state, int block);
    /// What sampleMotion() sums over, for a pass that takes the sums as it moves the particles
    /// (kickDriftSampled); recordMotion() keeps a block's, in place of sampleMotion().
    GuardInput motionInput(const State& state) const;
    void recordMotion(int block, const GuardSums& sums);
    void endMotion() { motionReady_ = true; }
    void forgetMotion() { motionReady_ = false; }

    /// What a checkpoint keeps (sim/StateArchive.h): the energy budget and the growth watch.
    template <class Self, class Archive>
    static void visitState(Self& s, Archive& a) {
        a(s.budget_), a(s.started_), a(s.lastKinetic_), a(s.growingSteps_), a(s.growthProduct_);
    }

private:
    void sampleBlock(const State& state, int begin, int end, Sample& out) const;
    [[noreturn]] void report(const State& state, const Sample& s, const std::string& why) const;
    void addWork(const State& state, const Sample& s);
    static void reduce(Domain& domain, Sample& s);

    double safety_ = 0.8;  ///< time.safety, for the advice on adaptive steps
    double speedLimit_ = kLightSpeed;
    Eigen::Vector3d gravity_ = Eigen::Vector3d::Zero();
    bool hasGravity_ = false;
    double pressureArea_ = 0.0;   ///< |p| times four times the rest area (stretched sheet) [N]
    double thermalEnergy_ = 0.0;  ///< E alpha^2 V: energy per theta^2 expansion can store [J]
    double floor_ = 0.0;          ///< budget never below this [J]
    double budget_ = 0.0;         ///< upper bound on the energy the run holds [J]
    bool started_ = false;
    double lastKinetic_ = 0.0;
    double checkedSpeedSquared_ = -1.0;
    int growingSteps_ = 0;
    double growthProduct_ = 1.0;
    mutable std::vector<Sample> blocks_;
    std::vector<Sample> motion_;  ///< sampleMotion()'s, per block of [motionFirst_, motionLast_)
    int motionFirst_ = 0, motionLast_ = 0;
    bool motionReady_ = false;
};

}  // namespace rend::sim
