#include "sim/Membrane.h"

#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include "sim/Fracture.h"
#include "sim/Material.h"
#include "sim/SolverRegistry.h"
#include "sim/StepKernels.h"

namespace rend::sim {

Membrane::Membrane(const MembraneParams& given)
    : params_(withCrackBandSoftening(withPreviewStrength(given))),
      lattice_(generateLattice(given.sheet)) {
    const MembraneParams& params = params_;
    const SheetParams& sheet = params.sheet;
    horizon_ = sheet.horizonFactor * sheet.dx;
    x0_ = lattice_.positions;
    const int n = int(x0_.size());
    if (n < 2) throw std::invalid_argument("the sheet holds fewer than two particles");
    volume_.assign(n, lattice_.particleArea * sheet.thickness);
    if (!lattice_.areas.empty())
        for (int i = 0; i < n; ++i) volume_[i] = lattice_.areas[i] * sheet.thickness;
    mass_.resize(n);
    const std::vector<double> density =
        materialFactors(MappedProperty::Density, params.materialMaps, x0_);
    for (int i = 0; i < n; ++i) mass_[i] = params.material.density * density[i] * volume_[i];
    const bool one = std::all_of(mass_.begin(), mass_.end(), [&](double m) {
        return std::bit_cast<std::uint64_t>(m) == std::bit_cast<std::uint64_t>(mass_[0]);
    });
    oneMass_ = one && mass_[0] > 0.0 && std::isfinite(mass_[0]) ? mass_[0] : 0.0;
    bonds_ = buildBondFamilies(x0_, horizon_);
    damageState_ = DamageState(bonds_, lattice_.triangles);
    const Material material(params.material);  // validated once, for every solver
    useSolver(solverEntry(params.solver).make({params, material, lattice_, bonds_, x0_, volume_}));
    setUpNotches(params);
    assignBoundaries();
    x_ = x0_;
    end_ = n;
    const std::vector<double> heights = perturbationHeights(sheet, x0_);
    for (int i = 0; i < n; ++i) x_[i].z() += heights[i];
    for (const Eigen::Vector3d& x : x_) extent_ = std::max(extent_, x.cwiseAbs().maxCoeff());
    v_.assign(n, Eigen::Vector3d::Zero());
    force_.assign(n, Eigen::Vector3d::Zero());
    if (Diffusion::needed(params)) {
        diffusion_.emplace(params, x0_, bonds_, volume_);
        theta_ = diffusion_->initialTheta();
        if (params.material.law == BondLawKind::PowerLaw) diffusion_->measureChanges();
    }
    if (params.contact.any()) setUpContact(params);
    if (params.remesh.every > 0) remesher_.emplace(x0_, bonds_, sheet.dx);
    if (params.particleLevelSet && sheet.outline != Outline::Sphere) {
        levelSet_.emplace(makeLevelSet());
        levelSet_->start(x_, damageState_.bondAlive());
    }
    dt_ = params.time.dt.value_or(params.time.safety * stableDt_);
    controller_ = TimeStepController(params.time);
    const MaterialParams& m = params.material;
    if (m.fractureEnergy)
        criticalStretch_ = std::sqrt(2.0 * std::numbers::pi * *m.fractureEnergy /
                                     (3.0 * m.youngsModulus * horizon_));
    updateDamage();
}

ParticleLevelSet Membrane::makeLevelSet() const {
    return ParticleLevelSet(params_.sheet, x0_, lattice_.triangles, bonds_.offsets,
                            bonds_.partners);
}

void Membrane::setStableStep(double worstRatio) {
    stableDt_ = std::sqrt(2.0 / worstRatio);
    guard_ = BlowUpGuard(params_, worstRatio, mass_, volume_);
}

void Membrane::useSolver(std::unique_ptr<Solver> solver) {
    solver_ = std::move(solver);
    solver_->bind(bonds_, damageState_);
    workspace_ = solver_->makeWorkspace();
    const std::vector<double> k = solver_->stiffnessRowSums(particleCount());
    double worstRatio = 0.0;
    for (int i = 0; i < particleCount(); ++i) worstRatio = std::max(worstRatio, k[i] / mass_[i]);
    setStableStep(worstRatio);
}

void Membrane::setUpNotches(const MembraneParams& params) {
    const MaterialParams& m = params.material;
    std::vector<std::array<int, 2>> edges;
    for (const int b : notchedBonds(params.notches, x0_, bonds_)) {
        damageState_.breakBond(b);
        const int i = int(std::upper_bound(bonds_.offsets.begin(), bonds_.offsets.end(), b) -
                          bonds_.offsets.begin()) -
                      1;
        if (i < bonds_.partners[b]) edges.push_back({i, bonds_.partners[b]});
    }
    notched_ = edges.size();
    if (notched_ > 0) solver_->cut(edges);
    canDamage_ =
        m.fractureEnergy.has_value() || m.law == BondLawKind::Elastoplastic || notched_ > 0;
}

void Membrane::assignBoundaries() {
    constraint_.assign(x0_.size(), kFree);
    for (int k = 0; k < int(params_.boundaries.size()); ++k) {
        const BoundaryCondition& bc = params_.boundaries[k];
        const std::int16_t tag = bc.kind == BoundaryKind::Pinned ? kPinned : std::int16_t(k);
        for (int i = 0; i < particleCount(); ++i)
            if (bc.region.contains(x0_[i])) constraint_[i] = tag;
    }
    free_.resize(x0_.size());
    for (std::size_t i = 0; i < x0_.size(); ++i) free_[i] = constraint_[i] == kFree;
}

// The contact thickness d defaults to half the spacing, never below the sheet's thickness. The
// self-contact's stiffness per unit mass at rest is a quarter of the stiffest rest row's
// (2 / dt_stable^2), and at least what holds 8 layers of sheet under gravity within d / 4; the
// stable bound then takes up to four such contacts at once (a particle's mass against a pair's
// reduced mass of half of it).
void Membrane::setUpContact(const MembraneParams& params) {
    const SelfContactParams& self = params.contact.self;
    const double thickness = self.thickness > 0.0
                                 ? self.thickness
                                 : std::max(0.5 * params.sheet.dx, params.sheet.thickness);
    const double restRate = 2.0 / (stableDt_ * stableDt_);
    const double baseRate =
        std::max(0.25 * restRate, 4.0 * 8.0 * params.gravity.norm() / thickness);
    contact_.emplace(params.contact, thickness, horizon_, baseRate, lattice_.triangles, x0_);
    if (self.enabled) setStableStep(restRate + 2.0 * baseRate);
}

int Membrane::nearestParticle(const Eigen::Vector2d& at) const {
    int best = 0;
    for (int i = 1; i < particleCount(); ++i)
        if ((x0_[i].head<2>() - at).squaredNorm() < (x0_[best].head<2>() - at).squaredNorm())
            best = i;
    return best;
}

std::vector<int> Membrane::boundaryParticleCounts() const {
    std::vector<int> counts(params_.boundaries.size(), 0);
    for (int k = 0; k < int(params_.boundaries.size()); ++k)
        for (int i = 0; i < particleCount(); ++i)
            if (params_.boundaries[k].region.contains(x0_[i])) ++counts[k];
    return counts;
}

void Membrane::computeForces(std::vector<Eigen::Vector3d>& force) const {
    solver_->forces(stepState(), *solver_->makeWorkspace(), force);
}

Eigen::Vector3d Membrane::boundaryVelocity(int k, double t) const {
    const BoundaryCondition& bc = params_.boundaries[k];
    const double ramp = bc.rampTime > 0.0 ? std::min(1.0, t / bc.rampTime) : 1.0;
    return ramp * bc.velocity;
}

// Eq. 26's velocity update of particle i over h: free particles by their force, gravity and
// damping; pinned ones stay at rest; driven ones take their boundary's velocity at tNext.
void Membrane::updateVelocity(int i, double h, double tNext, const Eigen::Vector3d& gravity,
                              double damping) {
    const std::int16_t c = constraint_[i];
    if (c == kFree)
        v_[i] += h * (force_[i] / mass_[i] + gravity - damping * v_[i]);
    else if (c == kPinned)
        v_[i].setZero();
    else
        v_[i] = boundaryVelocity(c, tNext);
}

void Membrane::kick(double h, double tNext) {
    speedBound_ = -1.0;
    const int n = particleCount();
    const Eigen::Vector3d gravity = params_.gravity;
    const double damping = params_.damping;
    forEachIndex(n >= kParallelThreshold, begin_, end_,
                 [&](int i) { updateVelocity(i, h, tNext, gravity, damping); });
}

void Membrane::checkFinite(const GuardSums* thetaSums) {
    BlowUpGuard::State state{
        x_,     v_,    force_, x0_,       mass_,         theta_,         constraint_,
        steps_, time_, dt_,    stableDt_, adaptiveStep_, colliderWork(), domain_};
    state.oneMass = oneMass_;
    state.thetaSums = thetaSums;
    guard_.check(state, [this] { return totalEnergy(); });
    // The check read every free particle's v (over every process), the pinned are at rest and
    // the driven at most at their boundary's full speed: a bound on every speed until v next
    // changes, so that the next force pass need not read v for it.
    double bound = std::sqrt(std::max(0.0, guard_.checkedSpeedSquared()));
    for (const BoundaryCondition& bc : params_.boundaries)
        bound = std::max(bound, bc.velocity.norm());
    speedBound_ = std::isfinite(bound) ? bound : -1.0;
}

// Eq. 26 in one pass per particle: velocity, then position. Symplectic Euler is the leapfrog
// with velocities half a step behind the positions, so where the step changes from h' to h the
// kick spans the half steps either side, (h' + h) / 2 (variable-step Stormer-Verlet). A kick of
// h alone shifts the modified energy the scheme conserves by O(h) each time the step changes;
// the adaptive step changes it thousands of times, and at half the bound that heated the lattice
// until a brittle sheet shattered (seaweed at 46K particles: 103,185 bonds broken against 1,324
// at a constant step). At a constant step the kick is h exactly, bit for bit.
void Membrane::integrate(double dt, double tNext, std::optional<bool> moved) {
    const double kickDt = kickBefore(dt);
    lastDrift_ = dt;
    speedBound_ = -1.0;
    const int n = particleCount();
    const Eigen::Vector3d gravity = params_.gravity;
    const double damping = params_.damping;
    if (moved) {  // the force pass kicked and drifted them (stepSymplecticEuler)
        collide(tNext, *moved);
    } else if (solver_->carriesMomentum()) {  // MPM: the kick, the grid, then the drift
        forEachIndex(n >= kParallelThreshold, 0, n,
                     [&](int i) { updateVelocity(i, kickDt, tNext, gravity, damping); });
        if (contact_ && contact_->hasColliders()) contact_->place(tNext - dt);
        solver_->transferMomentum({x_, mass_, free_, dt, contact_ ? &*contact_ : nullptr}, v_);
        forEachIndex(n >= kParallelThreshold, 0, n, [&](int i) { x_[i] += dt * v_[i]; });
        collide(tNext);
    } else {
        collide(tNext, kickAndDrift(kickDt, dt, tNext));
    }
    if (domain_) exchangeMotion();
}

// updateVelocity and the drift in one pass (sim/StepKernels.h: the same bits), by blocks.
// Returns whether a free particle may touch the ground where the ground is the only collider
// (true wherever there are other colliders or none of this kind).
KickDrift Membrane::kickDriftOf(double h, double dt, double tNext,
                                std::vector<double>& prescribed) {
    prescribed.assign(3 * params_.boundaries.size(), 0.0);
    for (std::size_t b = 0; b < params_.boundaries.size(); ++b) {
        const Eigen::Vector3d velocity = boundaryVelocity(int(b), tNext);
        for (int a = 0; a < 3; ++a) prescribed[3 * b + a] = velocity[a];
    }
    KickDrift k{x_.data()->data(),
                v_.data()->data(),
                force_.data()->data(),
                mass_.data(),
                constraint_.data(),
                prescribed,
                h,
                dt,
                {},
                params_.damping};
    k.oneMass = oneMass_;
    for (int a = 0; a < 3; ++a) k.gravity[a] = params_.gravity[a];
    k.floor = contact_ ? contact_->groundOnlyFloor() : Contact::kNoFloor;
    return k;
}

BlowUpGuard::State Membrane::motionState() const {
    BlowUpGuard::State moved{{}, v_, force_, {}, mass_, {}, constraint_};
    moved.oneMass = oneMass_;
    return moved;
}

bool Membrane::kickAndDrift(double h, double dt, double tNext) {
    std::vector<double> prescribed;
    const KickDrift k = kickDriftOf(h, dt, tNext, prescribed);
    const double floor = k.floor;
    // The guard's blocks: each is sampled for the step's check right after it moved, in cache.
    constexpr int kBlock = BlowUpGuard::kBlock;
    const int blocks = (end_ - begin_ + kBlock - 1) / kBlock;
    const BlowUpGuard::State moved = motionState();
    guard_.beginMotion(begin_, end_);
    const GuardInput sample = guard_.motionInput(moved);
    // Each block's sums taken in the kick's own loop (kickDriftSampled: sampleMotion()'s bits).
    const auto move = [&](int b, bool& below) {
        bool under = false;
        guard_.recordMotion(b, kickDriftSampled(k, sample, begin_ + b * kBlock,
                                                std::min(end_, begin_ + (b + 1) * kBlock), under));
        below = under || below;
    };
    bool below = false;
    if (wakesTeam(end_ - begin_ >= kParallelThreshold)) {
#pragma omp parallel for schedule(static) reduction(|| : below)
        for (int b = 0; b < blocks; ++b) move(b, below);
    } else {
        for (int b = 0; b < blocks; ++b) move(b, below);
    }
    guard_.endMotion();
    return floor == Contact::kNoFloor || below;
}

void Membrane::collide(double tNext, bool mayTouch) {
    collided_ = false;
    if (!contact_ || !contact_->hasColliders()) return;
    collided_ = mayTouch;
    const double t0 = omp_get_wtime();
    contact_->place(tNext);
    if (mayTouch) {
        contact_->resolveColliders(x_, v_, mass_, free_, begin_, end_);
        guard_.forgetMotion();  // the colliders may have moved some
    } else
        contact_->touchNothing();
    contactSeconds_ += omp_get_wtime() - t0;
}

// The ground alone sets no limit: nothing is spent finding the fastest particle for it.
double Membrane::contactStepLimit() const {
    return contact_ && contact_->limitsStep() ? contact_->stepLimit(slabMaxSpeed())
                                              : std::numeric_limits<double>::infinity();
}

void Membrane::accumulateForces(BlockMotion* motion, double* approachRate) {
    StepState s = stepState();
    s.stiffeningNeeded = stiffeningNeeded();
    s.motion = motion;
    // Where a particle was at most guard_.speedLimit() for time_, it lies within
    // positionScale.
    s.sinceLastPass = {driftSincePass_, diffusion_ ? diffusion_->lastChange() : 0.0,
                       extent_ + guard_.speedLimit() * time_};
    const FailureApproach approach = failureApproach();
    if (approachRate) s.approach = &approach, s.approachRate = approachRate;
    solver_->advance(s, *workspace_, force_);
    driftSincePass_ = -1.0;
    stiffening_ = domain_ ? domain_->max(solver_->stiffening()) : solver_->stiffening();
    if (approachRate && domain_) *approachRate = domain_->max(*approachRate);
    if (params_.pressure != 0.0) addPressure(force_);
    if (contact_ && contact_->selfContact()) {
        const double t0 = omp_get_wtime();
        contact_->addSelfContactForces({x_, v_, x0_, mass_, damageState_.keptTriangles(), dt_},
                                       force_);
        contactSeconds_ += omp_get_wtime() - t0;
    }
}

// Follower pressure: each kept triangle (DamageState::keptTriangles) pushes its three corners along
// its current area vector, p A n / 3 each. A serial loop in triangle order keeps the sums identical
// for any thread count; it runs only when a scene sets a pressure.
void Membrane::addPressure(std::vector<Eigen::Vector3d>& force) const {
    const auto& triangles = lattice_.triangles;
    const std::vector<std::uint8_t>& kept = damageState_.keptTriangles();
    for (std::size_t t = 0; t < triangles.size(); ++t) {
        if (!kept[t]) continue;
        const auto& [a, b, c] = triangles[t];
        const Eigen::Vector3d area = 0.5 * (x_[b] - x_[a]).cross(x_[c] - x_[a]);
        const Eigen::Vector3d share = params_.pressure * area / 3.0;
        force[a] += share;
        force[b] += share;
        force[c] += share;
    }
}

// A fixed step is also cut where contact needs it; an adaptive one was already chosen within the
// contact's limit (advanceTo).
int Membrane::piecesOfStep() {
    const double contactPieces =
        contact_ && !adaptiveStep_ ? std::ceil(dt_ / contactStepLimit() * (1.0 - 1e-12)) : 1.0;
    if (stiffening_ <= 1.0 && contactPieces <= 1.0) return 1;
    const double needed = std::max(contactPieces, stiffeningPieces(stiffening_));
    const int pieces = int(std::clamp(needed, 1.0, double(kMaxPieces)));
    subSteps_ += pieces - 1;
    return pieces;
}

// The pieces a fixed step needs for a stiffening: the bound scales as 1/sqrt(stiffness). Keep
// dt / bound within what was allowed at rest: the safety factor, or the step's own ratio when it
// was set higher.
double Membrane::stiffeningPieces(double stiffening) const {
    const double allowed = std::max(params_.time.safety, dt_ / stableDt_) * stableDt_;
    return std::ceil(dt_ * std::sqrt(std::max(1.0, stiffening)) / allowed * (1.0 - 1e-12));
}

// The largest stiffening that leaves a fixed step whole ((allowed / dt)^2, checked by
// stiffeningPieces itself): any stiffening up to it gives piecesOfStep the same answer, so the
// solver need not find it exactly (the power law's look-ahead then reads only the bonds that
// could squash past it). An adaptive step's size follows the stiffening itself: 1.
double Membrane::stiffeningNeeded() const {
    if (adaptiveStep_ || !(dt_ > 0.0)) return 1.0;
    const double allowed = std::max(params_.time.safety, dt_ / stableDt_) * stableDt_;
    const double whole = (allowed / dt_) * (allowed / dt_);
    return std::isfinite(whole) && whole > 1.0 && stiffeningPieces(whole) <= 1.0 ? whole : 1.0;
}

namespace {

// Membrane's kick and drift of each block the solver's pass hands over (StepState::motion), and
// the blow-up guard's sample of each of the guard's blocks: in the kick's own loop where the
// pass hands over the whole block (kickDriftSampled, as kickAndDrift), else once all of it has
// moved, by the thread that moved its last particles. The separate pass's kernels and sums over
// the same blocks, so the same bits.
class KickInPass final : public BlockMotion {
public:
    KickInPass(const KickDrift& kick, double* forceArray, BlowUpGuard& guard,
               const BlowUpGuard::State& state, int first, int last)
        : kick_(kick),
          forceArray_(forceArray),
          guard_(guard),
          state_(state),
          sample_(guard.motionInput(state)),
          first_(first),
          last_(last) {
        constexpr int kBlock = BlowUpGuard::kBlock;
        const int blocks = (last - first + kBlock - 1) / kBlock;
        left_ = std::make_unique<std::atomic<int>[]>(std::size_t(blocks));
        for (int b = 0; b < blocks; ++b)
            left_[b].store(std::min(last, first + (b + 1) * kBlock) - (first + b * kBlock));
        guard_.beginMotion(first, last);
    }
    void move(int begin, int end, const double* block, int first) override {
        KickDrift k = kick_;
        if (block) k.force = block, k.forceFirst = first, k.keptForce = forceArray_;
        bool below = false;
        constexpr int kBlock = BlowUpGuard::kBlock;
        for (int i = begin; i < end;) {
            const int b = (i - first_) / kBlock, blockBegin = first_ + b * kBlock;
            const int blockEnd = std::min(last_, blockBegin + kBlock),
                      stop = std::min(end, blockEnd);
            if (i == blockBegin && stop == blockEnd) {
                bool under = false;
                guard_.recordMotion(b, kickDriftSampled(k, sample_, i, stop, under));
                below = below || under;
            } else {
                below = kickDrift(k, i, stop) || below;
                if (left_[b].fetch_sub(stop - i, std::memory_order_acq_rel) == stop - i)
                    guard_.sampleMotion(state_, b);
            }
            i = stop;
        }
        if (below) below_.store(true, std::memory_order_relaxed);
        moved_.fetch_add(end - begin, std::memory_order_relaxed);
    }
    int moved() const { return moved_.load(); }
    /// kickAndDrift's answer: whether a free particle may touch the ground.
    bool below() const { return kick_.floor == Contact::kNoFloor || below_.load(); }

private:
    KickDrift kick_;
    double* forceArray_;
    BlowUpGuard& guard_;
    BlowUpGuard::State state_;
    GuardInput sample_;
    int first_, last_;
    std::unique_ptr<std::atomic<int>[]> left_;
    std::atomic<int> moved_{0};
    std::atomic<bool> below_{false};
};

}  // namespace

// Nothing may add to the forces between the solver's pass and the kick, and the step must be
// one piece (the pass cannot take back a kick): a fixed step is cut only by the power law's
// stiffening, whose pass moves only where the last pass shows it cannot cut this step
// (PeridynamicBonds::lookAheadClear, from driftSincePass_), and by colliders or self-contact (the
// ground alone limits nothing, and it pushes out after the drift as before).
bool Membrane::mayKickInPass() const {
    return kickInPass_ && !chooseAfterForces_ && !solver_->carriesMomentum() &&
           params_.pressure == 0.0 && !(contact_ && contact_->limitsStep());
}

// The pass must read nothing the step's length sets: not the power law's look-ahead, not the
// self-contact's (which reads dt), and no kick in it (mayKickInPass).
bool Membrane::approachInPass() const {
    return approachInPass_ && std::isfinite(criticalStretch_) &&
           params_.time.integrator == Integrator::SymplecticEuler &&
           solver_->measuresApproachInPass() && !(contact_ && contact_->selfContact());
}

void Membrane::stepSymplecticEuler() {
    std::vector<double> prescribed;
    std::optional<KickInPass> inPass;
    if (mayKickInPass())
        inPass.emplace(kickDriftOf(kickBefore(dt_), dt_, time_ + dt_, prescribed),
                       force_.data()->data(), guard_, motionState(), begin_, end_);
    // An adaptive step's length may wait for this pass: it measures the last step's failure
    // approach rate at x^n, v^n, theta^n, as a pass of its own after that step would have.
    const bool measure = chooseAfterForces_ && unrecorded_;
    double rate = 0.0;
    accumulateForces(inPass ? &*inPass : nullptr, measure ? &rate : nullptr);  // at x^n
    if (chooseAfterForces_) {
        if (measure) recordStep(rate), ++approachesInPass_;
        (*chooseAfterForces_)();
    }
    const int pieces = piecesOfStep();
    keptKickInPass_ = inPass && inPass->moved() > 0;
    if (keptKickInPass_) {
        if (pieces != 1 || inPass->moved() != end_ - begin_)
            throw std::logic_error("the force pass moved the particles of a step in pieces");
        guard_.endMotion();
        integrate(dt_, time_ + dt_, inPass->below());
        forcesCurrent_ = false;
        driftSincePass_ = collided_ || domain_ ? -1.0 : dt_;
        return;
    }
    double done = 0.0;
    for (int k = 0; k < pieces; ++k) {
        if (k > 0) accumulateForces();
        const double h = (dt_ - done) / (pieces - k);
        integrate(h, time_ + done + h);
        done += h;
    }
    forcesCurrent_ = false;
    driftSincePass_ = collided_ || domain_ || pieces != 1 ? -1.0 : dt_;
}

void Membrane::stepVelocityVerlet() {
    const int n = particleCount();
    if (!forcesCurrent_) accumulateForces();  // at x^n, unless the last step left them
    const int pieces = piecesOfStep();
    double done = 0.0;
    for (int k = 0; k < pieces; ++k) {
        const double h = (dt_ - done) / (pieces - k);
        kick(0.5 * h, time_ + done + h);
        forEachIndex(n >= kParallelThreshold, 0, n, [&](int i) { x_[i] += h * v_[i]; });
        accumulateForces();  // at x^n+1
        kick(0.5 * h, time_ + done + h);
        if (solver_->carriesMomentum())
            solver_->transferMomentum({x_, mass_, free_, h, contact_ ? &*contact_ : nullptr}, v_);
        done += h;
    }
    forcesCurrent_ = true;
}

void Membrane::step() {
    guard_.forgetMotion();  // sampled again if the step ends with kickAndDrift()
    if (params_.time.integrator == Integrator::VelocityVerlet)
        stepVelocityVerlet();
    else
        stepSymplecticEuler();
    if (remesher_ && (steps_ + 1) % params_.remesh.every == 0) {
        remesher_->remesh(x_, v_, mass_, damageState_.bondAlive(), free_);
        guard_.forgetMotion();
        driftSincePass_ = -1.0;
        forcesCurrent_ = false;
    }
    if (diffusion_) {
        diffusion_->advance(theta_, damageState_, time_,
                            dt_);  // theta^n -> theta^n+1 (and its ghosts, decomposed)
        forcesCurrent_ = false;
    }
    if (levelSet_)
        levelSet_->advance(x_, v_, damageState_.bondAlive(), damageState_.brokenBondCount(), dt_,
                           steps_ + 1);
    time_ += dt_;
    ++steps_;
    if (contact_) contact_->place(time_);
    dtMin_ = std::min(dtMin_, dt_);
    dtMax_ = std::max(dtMax_, dt_);
    // theta's half of the guard's sums, taken by the diffusion as it wrote theta (crack_path_
    // sources, power law, 10^7 particles: a pass over theta of its own was 1.5% of the samples,
    // the shipped foil at final quality 1.7%).
    checkFinite(diffusion_ ? diffusion_->thetaSums() : nullptr);
}

// Broken bonds, and the triangles element erosion removed (its bonds may stay intact).
std::size_t Membrane::breakCount() const {
    if (!domain_) return damageState_.brokenBondCount() + damageState_.removedTriangleCount();
    const std::vector<std::uint8_t>& alive = damageState_.bondAlive();
    const auto first = alive.begin() + bonds_.offsets[begin_];
    const auto last = alive.begin() + bonds_.offsets[end_];
    // Both copies of every broken bond, over all slabs: twice the one process's count.
    return std::size_t(domain_->sum(double(std::count(first, last, 0)))) / 2;
}

// The same guard as a fixed step's sub-steps (piecesOfStep): a bond squashed far past what any
// sheet shows (a collapsed lattice cell in a crumple) slows the step at most kMaxPieces-fold, or
// one bond of a million would set the step of the whole sheet.
double Membrane::currentStableTimeStep() const {
    return stableDt_ / std::min(std::sqrt(stiffening_), double(kMaxPieces));
}

// Only bonds that a step could carry past eta_c count. A bond loaded past eta_c / 2 and
// stretching at ds/dt > 0 has eta_c - s to go. A step closes at most half of that (so a bond whose
// stretch accelerates is not carried far past eta_c in one step), and near eta_c at most
// delta eta_c (delta = max_stretch_increment): about five steps bring a bond from eta_c / 2 to
// breaking, in order with its neighbours. A loaded bond far from eta_c does not set the step
// however fast it rings (swelling patches, lattice-scale modes): the bound keeps that stable.
FailureApproach Membrane::failureApproach() const {
    const MaterialParams& m = params_.material;
    return {criticalStretch_, m.expansion, m.strengthLoss, params_.time.maxStretchIncrement};
}

double Membrane::failureApproachRate() const {
    if (!std::isfinite(criticalStretch_)) return 0.0;
    const int n = particleCount();
    const std::vector<std::uint8_t>& alive = damageState_.bondAlive();
    const MaterialParams& m = params_.material;
    const double delta = params_.time.maxStretchIncrement;
    const bool heated = !theta_.empty();
    if (const std::optional<double> fast =
            solver_->failureApproachRate(stepState(), failureApproach()))
        return domain_ ? domain_->max(*fast) : *fast;
    double fastest = 0.0;  // a maximum: the same for any thread count
    const auto rateOf = [&](int i, double& fastest) {
        for (int b = bonds_.offsets[i]; b < bonds_.offsets[i + 1]; ++b) {
            const int j = bonds_.partners[b];
            if (j < i || !alive[b]) continue;  // each bond once
            const Eigen::Vector3d xi = x_[j] - x_[i];
            const double rest = bonds_.restLength[b];
            const double thetaBar = heated ? 0.5 * (theta_[i] + theta_[j]) : 0.0;
            const double critical = criticalStretch_ * degradation(m.strengthLoss, thetaBar);
            // Loaded: |xi| / L0 - 1 - alpha theta > eta_c / 2, compared squared (no root).
            const double unstretched = 1.0 + m.expansion * thetaBar;
            const double loaded = rest * (unstretched + 0.5 * critical);
            if (!(critical > 0.0 && xi.squaredNorm() > loaded * loaded)) continue;
            const double length = xi.norm();
            const double rate = xi.dot(v_[j] - v_[i]) / (length * rest);  // ds/dt
            if (!(rate > 0.0)) continue;
            const double margin = critical - (length / rest - unstretched);
            fastest = std::max(fastest, rate / std::max(0.5 * margin, delta * critical));
        }
    };
    fastest = largestOverIndices(n >= kParallelThreshold, begin_, end_, fastest, rateOf);
    return domain_ ? domain_->max(fastest) : fastest;
}

void Membrane::recordStep(double failureRate) {
    controller_.record(unrecorded_->taken, unrecorded_->broken, failureRate);
    unrecorded_.reset();
}

// The last step of a frame is not clipped to a sliver: the time left is split evenly into as
// few steps as the controller allows. Each step is recorded with the failure approach rate after
// it; where approachInPass(), the next step's force pass measures that rate (the pass does not
// move the particles, and reads nothing the step's length sets), and the step's length is chosen
// after it, from the stable bound and contact limit before it: the same steps, without a pass
// over every pair of its own after each (the shipped foil at final quality: 14% of a run's
// samples). The frame's last step is recorded by such a pass, so that a frame ends recorded.
void Membrane::advanceTo(double tEnd) {
    const bool afterForces = approachInPass();
    while (time_ < tEnd) {
        const double stable = currentStableTimeStep(), contactLimit = contactStepLimit();
        bool last = false;  // the step ends the frame
        const std::function<void()> choose = [&] {
            const double wanted = std::min(controller_.next(stable), contactLimit);
            const double left = tEnd - time_;
            const double pieces = std::ceil(left / wanted * (1.0 - 1e-12));
            dt_ = pieces <= 1.0 ? left : left / pieces;
            last = pieces <= 1.0;
        };
        if (unrecorded_ && !afterForces) recordStep(failureApproachRate());
        if (!afterForces) choose();
        const std::size_t before = breakCount();
        adaptiveStep_ = true;
        chooseAfterForces_ = afterForces ? &choose : nullptr;
        struct Reset {
            Membrane& m;
            ~Reset() { m.adaptiveStep_ = false, m.chooseAfterForces_ = nullptr; }
        } reset{*this};
        step();
        if (last) time_ = tEnd;  // exactly, whatever the rounding of time_ + dt_
        unrecorded_ = UnrecordedStep{dt_, breakCount() - before};
    }
    if (unrecorded_) recordStep(failureApproachRate());
}

void Membrane::updateDamage() {
    if (!canDamage_) return;
    damage_.resize(particleCount());
    solver_->reportStrength(damageState_);
    const std::vector<std::uint8_t>& alive = damageState_.bondAlive();
    const std::vector<double>& strength = damageState_.strength();
    for (int i = 0; i < particleCount(); ++i) {
        double total = 0.0, intact = 0.0;
        for (int b = bonds_.offsets[i]; b < bonds_.offsets[i + 1]; ++b) {
            total += bonds_.weight[b];
            if (!alive[b]) continue;
            intact += bonds_.weight[b] * strength[b];
        }
        damage_[i] = total > 0.0 ? 1.0 - intact / total : 0.0;
    }
}

double Membrane::kineticEnergy() const {
    double sum = 0.0;
    for (int i = 0; i < particleCount(); ++i) sum += 0.5 * mass_[i] * v_[i].squaredNorm();
    return sum;
}

double Membrane::strainEnergy() const {
    return solver_->strainEnergy(stepState(), *solver_->makeWorkspace());
}

double Membrane::maxSpeed() const {
    const int n = particleCount();
    double fastest = 0.0;  // squared; a maximum is the same for any thread count
    fastest = largestOverIndices(n >= kParallelThreshold, 0, n, fastest, [&](int i, double& most) {
        most = std::max(most, v_[i].squaredNorm());
    });
    return std::sqrt(fastest);
}

double Membrane::maxTheta() const {
    return theta_.empty() ? 0.0 : *std::max_element(theta_.begin(), theta_.end());
}

std::size_t Membrane::brokenBondCount() const { return damageState_.brokenBondCount(); }

Eigen::Vector3d Membrane::totalMomentum() const {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (int i = 0; i < particleCount(); ++i) p += mass_[i] * v_[i];
    return p;
}

FrameView Membrane::view(int frame) const {
    FrameView v;
    v.frame = frame;
    v.time = time_;
    v.positions = x_;
    v.velocities = v_;
    v.restPositions = x0_;
    v.theta = theta_;
    v.damage = damage_;
    v.restTriangles = lattice_.triangles;
    v.bondOffsets = bonds_.offsets;
    v.bondPartners = bonds_.partners;
    v.bondRestLength = bonds_.restLength;
    v.bondAlive = damageState_.bondAlive();
    v.keptTriangles = damageState_.keptTriangles();
    v.triangleAlive = damageState_.triangleAlive();
    if (levelSet_) {
        v.levelSet = levelSet_->phi();
        v.ghostPositions = levelSet_->ghostPositions();
        v.ghostRestPositions = levelSet_->ghostRestPositions();
        v.ghostLevelSet = levelSet_->ghostPhi();
        v.ghostAnchors = levelSet_->ghostAnchors();
        v.bandTriangles = levelSet_->bandTriangles();
        v.bandKept = levelSet_->bandKept();
    }
    if (contact_) {
        v.colliders = contact_->colliders();
        v.colliderPoses = contact_->poses();
    }
    return v;
}

}  // namespace rend::sim
