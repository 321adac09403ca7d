#pragma once
// The accuracy-driven explicit step of time.dt = "adaptive". Table 1's fixed steps sit 60-120x
// below the stable bound, yet the bound alone (dt = "auto") leaves the broken-bond count of a
// running crack scattered: a step that moves a crack tip past several bonds at once decides
// their order by the step, not by the physics. So each step takes
//
//     dt = min(min(safety, 0.5) x bound,                    stability (Silling & Askari 2005)
//              min over loaded bonds with ds/dt > 0 of       accuracy: no bond jumps to eta_c
//                max((eta_c - s) / 2, delta eta_c) / (ds/dt) a step closes at most half a
//                                                            bond's way to eta_c, or delta =
//                                                            max_stretch_increment of eta_c
//              burst cap)                                    a step that broke many bonds
//                                                            shrinks the next
//
// and never grows by more than kGrowth over the step before, nor falls below 1/64 of the first
// term. Half the bound, not auto's 0.8: a step near the bound is stable but integrates the
// lattice-scale modes coarsely (symplectic Euler's frequency error grows as the step nears
// 2 / omega), and a crack tip reads them. At 0.8 (0.72 after evening out to frames) the preview
// crack of crack_path_sources stalls for 0.19 s after four bonds, then kinks off its line; at
// 0.35-0.7 it breaks the same bonds as at a quarter of the stretch increment (README "Adaptive
// time step"). The bound is the rest one over the square root of the solver's stiffening (the power
// law in compression), recomputed every step. The time to failure is measured on the Membrane's
// bond families (every particle pair within the cutoff R), which every solver has, so the same
// limit serves the bonds, the elements, the springs and SPH alike; breaks are the DamageState's
// broken bonds and removed triangles.
//
// Inputs are a maximum and counts, which no thread count changes: the steps, and so the run,
// are bitwise identical for any number of threads.

#include <cstddef>
#include <limits>

#include "sim/Params.h"

namespace rend::sim {

/// Which limit chose a step.
enum class StepLimit { Bound, Stretch, Burst, Growth, Count };

class TimeStepController {
public:
    static constexpr double kGrowth = 1.25;  ///< most a step grows over the one before
    /// A burst cuts the next step by at most this factor, so one violent step cannot stall a run.
    static constexpr double kMostShrink = 0.125;
    /// The most of the stable bound an adaptive step takes, whatever time.safety says.
    static constexpr double kMostOfBound = 0.5;

    TimeStepController() = default;
    explicit TimeStepController(const TimeParams& time);

    /// The step wanted next, given the stable bound now (rest bound / sqrt(stiffening)).
    double next(double stableDt);
    /// After a step of `taken` seconds (at most what next() wanted, less where a frame ended),
    /// which broke `broken` bonds and left `failureRate` = one over the shortest time in which a
    /// bond reaches its critical stretch (Membrane::failureApproachRate).
    void record(double taken, std::size_t broken, double failureRate);

    StepLimit lastLimit() const { return lastLimit_; }
    /// Steps each limit chose, indexed by StepLimit.
    const long* limitCounts() const { return counts_; }
    /// The most bonds one step broke.
    std::size_t largestBurst() const { return largestBurst_; }

    /// What a checkpoint keeps (sim/StateArchive.h).
    template <class Self, class Archive>
    static void visitState(Self& s, Archive& a) {
        a(s.failureRate_), a(s.wanted_), a(s.cap_), a(s.burst_), a(s.lastLimit_), a(s.counts_);
        a(s.largestBurst_);
    }

private:
    double safety_ = kMostOfBound;
    double burstBonds_ = 8;
    double failureRate_ = 0.0;  ///< 1 / the shortest time for a bond to fail
    double wanted_ = 0.0;       ///< what next() last returned
    double cap_ = std::numeric_limits<double>::infinity();  ///< growth and burst limits
    bool burst_ = false;  ///< cap_ comes from a burst, not from growth
    StepLimit lastLimit_ = StepLimit::Bound;
    long counts_[int(StepLimit::Count)] = {};
    std::size_t largestBurst_ = 0;
};

}  // namespace rend::sim
