#include "sim/TimeStep.h"

#include <algorithm>

namespace rend::sim {
namespace {

/// No limit cuts a step below this fraction of safety x the bound: a bond whose strength is all
/// but gone, or bursts in a row, cannot stall a run (the same floor as the power law's pieces).
constexpr double kSmallest = 1.0 / 64;

}  // namespace

TimeStepController::TimeStepController(const TimeParams& time)
    : safety_(std::min(time.safety, kMostOfBound)), burstBonds_(double(time.burstBonds)) {}

double TimeStepController::next(double stableDt) {
    double dt = safety_ * stableDt;
    StepLimit limit = StepLimit::Bound;
    if (failureRate_ * dt > 1.0) {
        dt = 1.0 / failureRate_;
        limit = StepLimit::Stretch;
    }
    if (cap_ < dt) {
        dt = cap_;
        limit = burst_ ? StepLimit::Burst : StepLimit::Growth;
    }
    dt = std::max(dt, kSmallest * safety_ * stableDt);
    wanted_ = dt;
    lastLimit_ = limit;
    ++counts_[int(limit)];
    return dt;
}

void TimeStepController::record(double taken, std::size_t broken, double failureRate) {
    failureRate_ = failureRate;
    largestBurst_ = std::max(largestBurst_, broken);
    cap_ = kGrowth * wanted_;
    burst_ = false;
    if (double(broken) <= burstBonds_) return;
    // Shrink in proportion, so the next step breaks about burstBonds bonds at the same rate.
    const double cut = taken * std::max(kMostShrink, burstBonds_ / double(broken));
    if (cut < cap_) {
        cap_ = cut;
        burst_ = true;
    }
}

}  // namespace rend::sim
