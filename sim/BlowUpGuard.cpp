#include "sim/BlowUpGuard.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <numeric>
#include <sstream>

#include "sim/Parallel.h"
#include "sim/StepKernels.h"
#include "sim/TimeStep.h"

namespace rend::sim {
namespace {

constexpr std::int16_t kFree = -1;

// A NaN or an overflow never becomes a limit: anything not below the cap is the cap.
double capped(double value, double cap) { return value < cap ? value : cap; }

}  // namespace

double suggestedTimeStep(double dt, double stableDt) {
    const double suggested = 0.5 * std::min(dt, stableDt);
    return std::isfinite(suggested) && suggested > 0.0 ? suggested : 0.0;
}

namespace {

/// Below this fraction of the stable limit a smaller step rarely helps: what grows is energy the
/// forces themselves put in (a non-conservative solver, a power-law sheet crushed flat).
constexpr double kWellBelowBound = 0.25;

void adviseOn(std::ostream& out, double dt, double stableDt, double suggested, bool adaptive,
              double safety) {
    if (dt <= kWellBelowBound * stableDt) {
        out << " The time step " << dt << " s is already " << std::setprecision(2) << stableDt / dt
            << std::setprecision(6)
            << " times below the stable limit, so a smaller one is unlikely to help: the forces "
               "put energy in (the two-parameter springs are not the gradient of an energy and "
               "can at large strain). Try another solver, add forces.damping, or slow the "
               "boundary velocities, gravity or pressure.";
        return;
    }
    out << " The time step " << dt << " s against the stable limit " << stableDt
        << " s is the usual cause; ";
    if (adaptive) {
        // The adaptive step follows the bound: a smaller safety scales every step down.
        out << "lower time.safety (now " << safety << ") or use a fixed dt";
        if (suggested > 0.0) out << " <= " << suggested;
        out << ", or slow the boundary velocities, gravity or pressure.";
        return;
    }
    if (suggested > 0.0)
        out << "use dt <= " << suggested << " (or dt = \"auto\")";
    else
        out << "use a smaller dt (or dt = \"auto\")";
    out << ", or slow the boundary velocities, gravity or pressure.";
}

}  // namespace

BlowUpGuard::BlowUpGuard(const MembraneParams& params, double worstRatio,
                         std::span<const double> mass, std::span<const double> volume) {
    // A runaway particle moves far faster than the fastest wave (~dx * omega_max), anything the
    // boundaries impose, or free fall over the whole run.
    double boundarySpeed = 0.0;
    for (const auto& bc : params.boundaries)
        boundarySpeed = std::max(boundarySpeed, capped(bc.velocity.norm(), kLightSpeed));
    const double waveSpeed = capped(params.sheet.dx * std::sqrt(worstRatio), kLightSpeed);
    const double fall =
        capped(params.gravity.norm(), kLightSpeed) * capped(params.time.duration, kLightSpeed);
    // Only the adaptive advice reads it: what that step takes, at most half the bound.
    safety_ = std::min(params.time.safety, TimeStepController::kMostOfBound);
    speedLimit_ = capped(100.0 * waveSpeed + 10.0 * boundarySpeed + 2.0 * fall + 1e-6, kLightSpeed);

    gravity_ = params.gravity.allFinite() ? params.gravity : Eigen::Vector3d::Zero();
    hasGravity_ = gravity_ != Eigen::Vector3d::Zero();
    const double totalVolume = std::accumulate(volume.begin(), volume.end(), 0.0);
    const double totalMass = std::accumulate(mass.begin(), mass.end(), 0.0);
    // A follower pressure does at most p A v of work per second; 4 A allows the sheet to
    // double in size.
    pressureArea_ = std::abs(params.pressure) * 4.0 * totalVolume / params.sheet.thickness;
    // A free expansion strain alpha theta held back costs at most E (alpha theta)^2 / 2 per
    // unit volume in each of two directions.
    const MaterialParams& m = params.material;
    thermalEnergy_ = m.youngsModulus * m.expansion * m.expansion * totalVolume;
    // Below the energy of the whole sheet moving at a thousandth of the wave speed, growth is
    // noise in a state at rest, not a blow-up.
    floor_ = 0.5 * totalMass * std::pow(1e-3 * waveSpeed, 2);
}

// One block's sums (sim/StepKernels.h: eight particles at a time with AVX-512). Only v is checked
// for finiteness: x moves by dt v from a finite start, so a non-finite x has had a non-finite v
// first (or one over the limit), and skipping it halves the memory the pass reads. The blocks
// are fixed, and each is summed in a fixed order: the same bits for any thread count.
namespace {

GuardInput guardInput(const BlowUpGuard::State& s, double limit, const Eigen::Vector3d& gravity,
                      bool hasGravity, bool theta) {
    return {s.v.data()->data(),
            s.force.empty() ? nullptr : s.force.data()->data(),
            s.mass.data(),
            s.constraint.data(),
            theta && !s.theta.empty() ? s.theta.data() : nullptr,
            limit * limit,
            {gravity.x(), gravity.y(), gravity.z()},
            hasGravity,
            s.oneMass};
}

BlowUpGuard::Sample sampleOf(const GuardSums& r) {
    return {r.kinetic,     r.boundaryPower, r.gravityPower, r.maxSpeedSquared,
            r.maxAbsTheta, r.fastest,       r.firstBad};
}

}  // namespace

void BlowUpGuard::sampleBlock(const State& s, int begin, int end, Sample& out) const {
    out = sampleOf(guardSums(guardInput(s, speedLimit_, gravity_, hasGravity_, true), begin, end));
}

void BlowUpGuard::beginMotion(int first, int last) {
    motionFirst_ = first, motionLast_ = last, motionReady_ = false;
    motion_.resize((last - first + kBlock - 1) / kBlock);
}

void BlowUpGuard::sampleMotion(const State& s, int block) {
    const int begin = motionFirst_ + block * kBlock, end = std::min(motionLast_, begin + kBlock);
    recordMotion(block, guardMotionSums(motionInput(s), begin, end));
}

GuardInput BlowUpGuard::motionInput(const State& s) const {
    return guardInput(s, speedLimit_, gravity_, hasGravity_, false);
}

void BlowUpGuard::recordMotion(int block, const GuardSums& sums) {
    motion_[block] = sampleOf(sums);
}

BlowUpGuard::Sample BlowUpGuard::sample(const State& s) const {
    const int first = s.domain ? s.domain->slab().begin : 0;
    const int n = s.domain ? s.domain->slab().end : int(s.v.size());
    const int blocks = (n - first + kBlock - 1) / kBlock;
    blocks_.assign(blocks, Sample{});
    // The motion the integrator sampled as it went, and theta now; else both now.
    const bool sampled = motionReady_ && motionFirst_ == first && motionLast_ == n;
    forEachIndex(n - first >= kParallelThreshold, 0, blocks, [&](int b) {
        const int begin = first + b * kBlock, end = std::min(n, begin + kBlock);
        if (!sampled) {
            sampleBlock(s, begin, end, blocks_[b]);
            return;
        }
        GuardSums sums{motion_[b].kinetic,      motion_[b].boundaryPower,
                       motion_[b].gravityPower, motion_[b].maxSpeedSquared,
                       motion_[b].maxAbsTheta,  motion_[b].fastest,
                       motion_[b].firstBad};
        if (!s.theta.empty() && !s.thetaSums)
            addThetaSums(sums, guardThetaSums(s.theta.data(), begin, end));
        blocks_[b] = sampleOf(sums);
    });
    Sample total;
    for (const Sample& b : blocks_) {
        total.kinetic += b.kinetic;
        total.boundaryPower += b.boundaryPower;
        total.gravityPower += b.gravityPower;
        total.maxAbsTheta = std::max(total.maxAbsTheta, b.maxAbsTheta);
        if (b.maxSpeedSquared > total.maxSpeedSquared) {
            total.maxSpeedSquared = b.maxSpeedSquared;
            total.fastest = b.fastest;
        }
        if (total.firstBad < 0) total.firstBad = b.firstBad;
    }
    // The largest |theta| and the lowest bad index over all blocks, as the blocks' own sums
    // would have joined them.
    if (sampled && !s.theta.empty() && s.thetaSums) {
        total.maxAbsTheta = std::max(total.maxAbsTheta, s.thetaSums->maxAbsTheta);
        const int bad = s.thetaSums->firstBad;
        if (bad >= 0 && (total.firstBad < 0 || bad < total.firstBad)) total.firstBad = bad;
    }
    if (s.domain) reduce(*s.domain, total);
    return total;
}

// Indices travel as minus themselves so that the maximum finds the lowest (-inf: none).
void BlowUpGuard::reduce(Domain& domain, Sample& s) {
    const double none = -std::numeric_limits<double>::infinity();
    double sums[] = {s.kinetic, s.boundaryPower, s.gravityPower};
    domain.sum(sums);
    double maxima[] = {s.maxSpeedSquared, s.maxAbsTheta, s.firstBad >= 0 ? -s.firstBad : none};
    domain.max(maxima);
    const double fastest =
        domain.max(s.maxSpeedSquared == maxima[0] && s.fastest >= 0 ? -s.fastest : none);
    s = {sums[0],
         sums[1],
         sums[2],
         maxima[0],
         maxima[1],
         fastest == none ? -1 : int(-fastest),
         maxima[2] == none ? -1 : int(-maxima[2])};
}

void BlowUpGuard::addWork(const State& state, const Sample& s) {
    const double power =
        s.boundaryPower + s.gravityPower + pressureArea_ * std::sqrt(s.maxSpeedSquared);
    budget_ += state.dt * power + state.colliderWork;
}

void BlowUpGuard::check(const State& state, const std::function<double()>& totalEnergy) {
    const Sample s = sample(state);
    motionReady_ = false;
    checkedSpeedSquared_ = -1.0;
    if (s.firstBad >= 0) report(state, s, "");
    checkedSpeedSquared_ = s.maxSpeedSquared;
    if (!started_) {
        started_ = true;
        budget_ = floor_ + std::max(0.0, totalEnergy());
        lastKinetic_ = s.kinetic;
        return;
    }
    addWork(state, s);
    const bool growing = s.kinetic >= kGrowth * lastKinetic_ && s.kinetic > 0.0;
    growingSteps_ = growing ? growingSteps_ + 1 : 0;
    growthProduct_ = growing ? growthProduct_ * s.kinetic / lastKinetic_ : 1.0;
    lastKinetic_ = s.kinetic;
    const double allowed = budget_ + thermalEnergy_ * s.maxAbsTheta * s.maxAbsTheta;
    const double ratio = s.kinetic / allowed;
    const bool fastGrowth = growingSteps_ >= kGrowthSteps && ratio > kBudgetFactor;
    if (!fastGrowth && !(ratio > kRunawayFactor)) return;
    std::ostringstream why;
    why.precision(3);
    if (fastGrowth)
        why << "the kinetic energy grew " << std::pow(growthProduct_, 1.0 / growingSteps_)
            << "x per step over the last " << growingSteps_ << " steps to ";
    else
        why << "the kinetic energy reached ";
    why << s.kinetic << " J, " << ratio
        << " times the most the start state, the boundaries, gravity, pressure, expansion "
           "and colliders can have put in ("
        << allowed << " J)";
    report(state, s, why.str());
}

void BlowUpGuard::report(const State& state, const Sample& s, const std::string& why) const {
    const int culprit = s.firstBad >= 0 ? s.firstBad : std::max(0, s.fastest);
    const double suggested = suggestedTimeStep(state.dt, state.stableDt);
    const Eigen::Vector3d& rest = state.restPositions[culprit];
    std::ostringstream out;
    out << "numerical blow-up at step " << state.step << " (t = " << state.time << " s): ";
    if (!why.empty()) out << why << "; the fastest particle is ";
    out << "particle " << culprit << " (rest position " << rest.x() << ", " << rest.y() << ")";
    const double speed = state.v[culprit].stableNorm();  // no overflow to inf
    if (!state.x[culprit].allFinite() || !state.v[culprit].allFinite())
        out << " has a position or velocity that is not finite.";
    else if (!state.theta.empty() && !std::isfinite(state.theta[culprit]))
        out << " has a diffusive quantity that is not finite.";
    else if (why.empty())
        out << " has speed " << speed << " m/s, beyond the plausible limit " << speedLimit_
            << " m/s.";
    else
        out << " at " << speed << " m/s.";
    adviseOn(out, state.dt, state.stableDt, suggested, state.adaptive, safety_);
    throw NumericalBlowUp(out.str(), state.step, culprit, suggested);
}

}  // namespace rend::sim
