// VALIDATION.md, "wave arrival, plane stress: c_p = sqrt(E / (rho (1 - nu^2))), within 2% for
// wavelength >= 10 delta".
//
// The left edge of a wide sheet is driven in x with a velocity that ramps linearly from 0 to v0
// over T_r = 10 delta / c_p and then stays at v0 (a smoothed step). In the middle of the sheet the
// front is a plane wave in uniaxial strain (the width keeps the lateral free edges out: their
// release waves reach the centre line at x only sqrt(x^2 + H^2)/c_p after the start, far behind
// the front). Behind a plane front the particle velocity equals the driving velocity, so the
// arrival at a probe line is when the mean x-velocity of its particles (|y| < 0.2 m) crosses
// v0 / 2, interpolated linearly between steps. The speed is the distance between two probe lines
// over the difference of their arrival times, which cancels the ramp's delay and the position of
// the driven edge. With the bond-based nu = 1/3, c_p = sqrt(9 E / (8 rho)).

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "tests/validation/checks/Mpm.h"

TEST(ValidationWave, PlaneStressPWaveFrontTravelsAtCpWithinTwoPercent) {
    // The set-up is checks/Mpm.h's planeWave, shared with the MPM's check (E = 2e4 Pa,
    // rho = 5000 kg/m^3, dx = 0.02, a 2.2 x 3 m sheet, probes 0.9 m apart).
    const double E = 2e4, rho = 5000, nu = 1.0 / 3.0;
    const double cp = std::sqrt(E / (rho * (1 - nu * nu)));
    const rend::checks::WaveFigures w = rend::checks::planeWave("peridynamic", 0.02, nu);
    const double error = w.speedOverCp - 1.0;
    std::printf(
        "P wave: %d particles, dx = 0.02: measured speed %.5f m/s, c_p = "
        "sqrt(E/(rho(1-nu^2))) = %.5f m/s, error %+.3f%%  (target 2%%)\n",
        w.particles, w.speedOverCp * cp, cp, 100 * error);
    EXPECT_LT(std::abs(error), 0.02);
}
