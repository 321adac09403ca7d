#pragma once
// Linear micro-spring law of the membrane paper (seeds/000, eqs. 12 and 18), written in a
// dimensionally consistent membrane form.
//
// The paper's bond energy is Psi = c eta^2 / 2 with strain eta = |r|/|r0| - 1 (eq. 10), and the
// force on i is f dEta/dq_i (eq. 17). We give a bond between particles of volumes V_i, V_j = A h
// the energy
//     U_ij = W0_ij V_i V_j c eta^2 / 2,
// so the force on i is  F_ij = c eta W0_ij V_i V_j / |r0| * r/|r|  along the CURRENT direction
// r/|r| (the derivative of eta is along it; the printed eq. 22 shows n0, which is not objective).
//
// Calibration: under a uniform isotropic strain eta = e on every bond, the energy density at an
// interior particle is (1/V_i) * 1/2 * sum_j U_ij = c e^2/4 * sum_j W0_ij V_j. A plane-stress
// continuum with nu = 1/3 (fixed by bond-based models) stores E e^2/(1 - nu) = 3/2 E e^2, so
//     c = 6 E / sum_j W0_ij V_j.
// In the continuum limit sum_j W0 V_j -> h * int_0^R (1 - r/R) 2 pi r dr = pi h R^2 / 3, giving
// c = 18 E / (pi h R^2). We use the discrete sum of an interior particle of the actual lattice,
// so the interior reproduces E exactly at any R/dx.
//
// The paper's literal constant c = 18K/(pi R^4) (eq. 24, K the bulk modulus) is kept as an option
// together with its literal eq. 22 (areas A_j instead of volumes); its units do not close, so its
// effective modulus depends on dx, R and h. The patch-test report prints both.

#include <cmath>
#include <numbers>

#include "sim/Params.h"

namespace rend::sim {

struct LinearBondLaw {
    double c = 0.0;  ///< micromodulus

    double force(double eta) const { return c * eta; }               ///< eq. 18 (no diffusion yet)
    double energy(double eta) const { return 0.5 * c * eta * eta; }  ///< eq. 12
    double stiffness() const { return c; }                           ///< d force / d eta at rest
};

/// c = 6E / sum_j W0_ij V_j, with `interiorWeightedVolume` = max over particles of that sum.
inline double calibratedMicromodulus(double youngsModulus, double interiorWeightedVolume) {
    return 6.0 * youngsModulus / interiorWeightedVolume;
}

/// Eq. 24 as printed: c = 18 K / (pi R^4), K = E / (3 (1 - 2 nu)).
inline double paperMicromodulus(double youngsModulus, double poissonRatio, double horizon) {
    const double bulk = youngsModulus / (3.0 * (1.0 - 2.0 * poissonRatio));
    return 18.0 * bulk / (std::numbers::pi * std::pow(horizon, 4));
}

}  // namespace rend::sim
