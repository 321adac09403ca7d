#pragma once
// Eq. 26's kick and drift in one pass over a range of particles, four free particles at a time
// with AVX2 where the CPU has it, else one at a time. Both use only +, -, * and / (no fused
// multiply-add), in the order of Membrane::updateVelocity, so their bits are the same.

#include <cstdint>
#include <span>

namespace rend::sim {

struct KickDrift {
    double* x = nullptr;  ///< x y z per particle
    double* v = nullptr;
    const double* force = nullptr;
    const double* mass = nullptr;
    /// -1 free, -2 pinned, k >= 0 driven by boundary k (Membrane's tags).
    const std::int16_t* constraint = nullptr;
    /// x y z per boundary: the prescribed velocity of its particles at the end of the step.
    std::span<const double> boundaryVelocity;
    double h = 0.0;   ///< the kick
    double dt = 0.0;  ///< the drift
    double gravity[3] = {0.0, 0.0, 0.0};
    double damping = 0.0;
};

/// Particles [begin, end): v += h (f / m + g - damping v) for the free ones, the pinned at rest,
/// the driven at their boundary's velocity; then x += dt v.
void kickDrift(const KickDrift& k, int begin, int end);

}  // namespace rend::sim
