#pragma once
// VALIDATION.md, "Hencky clamped circular membrane, uniform pressure: w0 = C a (p a / (E h))^(1/3),
// C = 0.6448 at nu = 1/3, within 2%".
//
// C re-derived for this check: shooting on the axisymmetric Foppl-Hencky equations
// r S'' + S' - S/r = -E h p^2 r^4 / (8 S^2) with S = r N_r, S'(a) = nu S(a)/a (no radial
// displacement at the rim) and w0 = int_0^a p r / (2 N_r) dr gives C = 0.64478 at nu = 1/3
// (0.65344 at nu = 0.3, Hencky's tabulated value), so 0.6448 holds for the bond-based nu = 1/3.
//
// Set-up: a disc (Outline::Disc) under a uniform follower pressure with gravity 0, damped to a
// static state. A Region is a box and cannot describe a ring, so the check clamps the rim itself:
// after every step it puts the particles with rest radius > a_c back at their rest positions
// with zero velocity (positions() and velocities() are writable). With symplectic Euler the
// forces of a step are computed at the start, so the free particles always see the ring exactly
// at rest. The clamped ring is thicker than the horizon delta, so every free particle keeps its
// whole family (no skin effect). The damping is about twice the fundamental frequency of the
// tensioned membrane, 2.405 c_m / a with c_m = sqrt(N0 / (rho h)) and N0 = 0.435
// (E h p^2 a^2)^(1/3) (the centre tension of the same Hencky solution).
//
// Where the clamp of the continuum membrane lies is only known to O(dx), so Result carries three
// candidate radii a for the reference (see their comments).
//
// Hencky's solution is Foppl's moderate-deflection theory, exactly self-similar in pa/(Eh); the
// bonds are geometrically exact and the pressure follows the surface. The two differ by a term
// of relative order (w0/a)^2 that refinement does not remove: bench/accuracy/hencky.cpp
// measures it (+0.55% of w0 at w0/a = 0.1).

#include "sim/Params.h"

namespace rend::checks {

constexpr double kHenckyC = 0.6448;  // nu = 1/3

struct Result {
    double w0;         ///< centre deflection at rest [m]
    double load;       ///< pressure [Pa], sized for w0 / a_c = sag in Hencky's formula
    double threshold;  ///< a_c: particles with rest radius > a_c are held
    double attached;   ///< mean rest radius of the held particles bonded to a free one
    double lastFree;   ///< mean rest radius of the free particles bonded to a held one
    int particles, free;
    double settleTime;  ///< simulated time at which the centre stopped moving [s]
};

/// Hencky's centre deflection C a (p a / (E h))^(1/3) of a disc of radius a.
double henckyDeflection(double a, double load, double Eh);

/// Disc of `radius` at spacing dx held outside a_c = radius - 2 dx, under the pressure that
/// Hencky's formula says deflects it by w0 = sag * a_c, solved to rest. E = 2e4 Pa, h = 1 mm,
/// rho = 5000 kg/m^3.
Result clampedDisc(double radius, double dx, double sag = 0.1);

/// The same set-up for any solver, material and load (the bubble inflation test).
struct DiscSpec {
    double radius = 0.5, dx = 0.025;
    double load = 0.0;  ///< pressure [Pa]; 0: the one for w0 = sag * a_c at nu = 1/3
    double sag = 0.1;
    std::string solver = "peridynamic";
    double youngsModulus = 2e4, poissonRatio = 1.0 / 3.0, thickness = 1e-3, density = 5000;
};
Result clampedDisc(const DiscSpec& spec);

}  // namespace rend::checks
