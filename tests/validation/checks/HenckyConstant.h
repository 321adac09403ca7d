#pragma once
// Hencky's constant C(nu) of the clamped circular membrane under uniform pressure,
// w0 = C a (p a / (E h))^(1/3), computed rather than tabulated so that any nu can be checked.
//
// Foppl-Hencky, axisymmetric, no bending: with rho = r / a and the radial stress resultant
// N_r = E h (p a / (E h))^(2/3) n(rho), equilibrium and compatibility give
//     rho^2 n'' + 3 rho n' + rho^2 / (8 n^2) = 0,   n'(0) = 0,
// and no radial displacement at the rim, N_theta = nu N_r with N_theta = (r N_r)', gives
//     n'(1) = (nu - 1) n(1).
// Shooting on n(0) (bisection, RK4 from the series n = n0 - rho^2 / (64 n0^2) near 0) and
// w0 = int_0^a p r / (2 N_r) dr = a (p a / (E h))^(1/3) int_0^1 rho / (2 n) drho give C.
// It reproduces Hencky's 0.6534 at nu = 0.3 and 0.6448 at nu = 1/3.

namespace rend::checks {

double henckyConstant(double poissonRatio);

}  // namespace rend::checks
