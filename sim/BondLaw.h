#pragma once
// Micro-spring laws of the membrane paper (seeds/000, eqs. 12-14 and 18-20), written in a
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

#include <algorithm>
#include <cmath>
#include <numbers>

#include "sim/LawExp.h"
#include "sim/Params.h"

namespace rend::sim {

/// Irreversible state of one bond of the elastoplastic law (eq. 20 and the damage of eq. 27):
/// the largest mechanical strain it has reached.
struct PlasticState {
    double maxStrain = 0.0;
};

/// One bond law with all three of the paper's forms. `eta` is always the mechanical strain: the
/// diffusion-driven part alpha * theta_bar is removed by the caller (eqs. 18-20 subtract it).
///
/// Every law is scaled so that its small-strain stiffness df/deta at rest is c, the calibrated
/// micromodulus: a scene's E means the same thing whatever the law.
struct BondLaw {
    BondLawKind kind = BondLawKind::Linear;
    double c = 0.0;  ///< micromodulus: df/deta at rest

    // Power law (eq. 13/19), with s = 1 + eta. The printed energy c (s^2 + 1/s^2) + c* s^n has
    // a non-zero force at rest; we subtract its value and slope at s = 1 so the rest state is
    // force- and energy-free:  Psi = cp (s^2 + s^-2 - 2) + c* (s^n - 1 - n (s - 1)).
    // Small-strain stiffness 8 cp + c* n (n - 1) = c fixes cp.
    double powerC = 0.0;
    double powerCStar = 0.0;  ///< c* = ratio * c, <= 0
    double powerN = 4.0;

    // Elastoplastic (eq. 14/20): linear up to eta0; loaded beyond, the bond follows eq. 20,
    // f = c eta0 exp(-beta (eta - eta0)/eta0), and its strength left is eq. 27's gamma at the
    // largest strain reached. Unloading is elastic (slope c) down to the permanent strain
    // eta_max - f(eta_max)/c, so a crumpled foil keeps its crumples.
    double yieldStrain = 1e-4;
    double softening = 1.0;

    static BondLaw fromMaterial(const MaterialParams& m, double micromodulus) {
        BondLaw law;
        law.kind = m.law;
        law.c = micromodulus;
        law.powerN = m.powerLawExponent;
        law.powerCStar = m.powerLawRatio * micromodulus;
        law.powerC = (micromodulus - law.powerCStar * law.powerN * (law.powerN - 1.0)) / 8.0;
        law.yieldStrain = m.yieldStrain;
        law.softening = m.softening;
        return law;
    }

    double stiffness() const { return c; }

    /// This law with a material map's factors on eq. 20's beta and on the power law's c*/c and
    /// n (eq. 19, issue 15). c is kept, and cp follows, so the small-strain stiffness stays c:
    /// such a map changes only how the sheet yields or stiffens, never its E.
    BondLaw scaled(double softeningFactor, double ratioFactor, double exponentFactor) const {
        BondLaw law = *this;
        law.softening *= softeningFactor;
        law.powerCStar *= ratioFactor;
        law.powerN *= exponentFactor;
        law.powerC = (c - law.powerCStar * law.powerN * (law.powerN - 1.0)) / 8.0;
        return law;
    }

    /// The most compression the power law is evaluated at (a bond squashed to 5% of its
    /// length): beyond it the push is held, and the explicit step's look-ahead stops there too.
    static constexpr double kMostCompression = -0.95;

    /// s^k for the power law: std::pow costs ~50 ns, most scenes use a small whole exponent.
    static double power(double s, double k) {
        if (k == 0.0) return 1.0;
        if (k == 1.0) return s;
        if (k == 2.0) return s * s;
        if (k == 3.0) return s * s * s;
        if (k == 4.0) return (s * s) * (s * s);
        return std::pow(s, k);
    }

    /// Eq. 19's force as numerator / cube, cube = s^3: 2C (s^4 - 1) + C* n (s^(n-1) - 1) s^3
    /// over s^3, which is 2C (s - 1/s^3) + C* n (s^(n-1) - 1). The pair kernels divide the
    /// force by the bond's length and the numerator by length x cube: one division where there
    /// were two. s^4 - 1 and, for the whole n of 2 to 4, s^(n-1) - 1 are factored by
    /// e = s - 1, without the cancellation of their differences near s = 1.
    struct PowerLawParts {
        double numerator, cube;
    };
    PowerLawParts powerLawParts(double eta) const {
        const double e = std::max(eta, kMostCompression), s = 1.0 + e, s2 = s * s;
        const double cube = s2 * s, quartic = e * (s + 1.0) * (s2 + 1.0);
        const double higher = powerN == 2.0   ? e
                              : powerN == 3.0 ? e * (s + 1.0)
                              : powerN == 4.0 ? e * (s2 + s + 1.0)
                                              : power(s, powerN - 1.0) - 1.0;
        return {2.0 * powerC * quartic + powerCStar * powerN * higher * cube, cube};
    }

    /// The pair kernels' eq. 19, from the bond's stretch times its rest length (length - rest,
    /// less rest alpha theta) for the whole n of 2 to 4: f / length = numerator / (denominator
    /// length), where powerLawParts' numerator / cube is numerator / denominator with both
    /// multiplied by rest^(n+2), so that no division is taken for eta: one in all.
    struct PowerLawByRest {
        double numerator, denominator;
    };
    PowerLawByRest powerLawByRest(double stretch, double rest) const {
        const double e = std::max(stretch, rest * kMostCompression), s = rest + e;
        const double s2 = s * s, cube = s2 * s, r2 = rest * rest;
        const double quartic = e * (s + rest) * (s2 + r2);
        const double higher = powerN == 2.0   ? e
                              : powerN == 3.0 ? e * (s + rest)
                                              : e * (s2 + s * rest + r2);
        const double low = powerN == 2.0 ? 1.0 : powerN == 3.0 ? rest : r2;
        const double high = powerN == 2.0 ? rest : powerN == 3.0 ? r2 : r2 * rest;
        return {2.0 * powerC * quartic * low + powerCStar * powerN * higher * cube, high * cube};
    }

    /// Eq. 20's force on the loading path at strain eta >= eta0 (lawExp: the vector kernels'
    /// bits).
    double yieldForce(double eta) const {
        return c * yieldStrain * lawExp((yieldStrain - eta) * (softening / yieldStrain));
    }

    /// Permanent strain left after loading to maxStrain (0 while it stayed elastic).
    double plasticStrain(const PlasticState& p) const {
        return p.maxStrain > yieldStrain ? p.maxStrain - yieldForce(p.maxStrain) / c : 0.0;
    }

    /// eq. 27's gamma: the fraction of strength left (1 for elastic laws).
    double strengthLeft(const PlasticState& p) const {
        return kind == BondLawKind::Elastoplastic && p.maxStrain > yieldStrain
                   ? yieldForce(p.maxStrain) / (c * yieldStrain)
                   : 1.0;
    }

    /// f(eta) = dPsi/deta for the elastic laws and the current elastoplastic state, for a law
    /// known at compile time (the force loop is compiled once per law).
    template <BondLawKind K>
    double forceAs(double eta, const PlasticState& p = {}) const {
        if constexpr (K == BondLawKind::Linear) {
            return c * eta;  // eq. 18
        } else if constexpr (K == BondLawKind::PowerLaw) {
            // Past kMostCompression the push stays at its value there (the energy goes on
            // linearly). Eq. 19 holds for s > 0 only: where the expansion alpha theta exceeds a
            // squashed bond's length, s = 1 + eta < 0 and s - 1/s^3 turns the push into a pull
            // that collapses the pair (the acid film's swollen shreds did).
            const PowerLawParts parts = powerLawParts(eta);  // eq. 19
            return parts.numerator / parts.cube;
        } else {
            if (eta >= p.maxStrain && eta > yieldStrain) return yieldForce(eta);  // eq. 20
            return c * (eta - plasticStrain(p));  // elastic, below the largest strain
        }
    }

    /// df/deta of the power law over its rest value c: it grows as s^-4 in compression, so
    /// the explicit step must shrink with it (Membrane::step sub-steps by its square root).
    double powerLawStiffening(double eta) const {
        const double s = 1.0 + eta, s2 = s * s;
        const double tangent = 2.0 * powerC * (1.0 + 3.0 / (s2 * s2)) +
                               powerCStar * powerN * (powerN - 1.0) * power(s, powerN - 2.0);
        return tangent / c;
    }

    double force(double eta, const PlasticState& p = {}) const {
        switch (kind) {
            case BondLawKind::Linear:
                return forceAs<BondLawKind::Linear>(eta, p);
            case BondLawKind::PowerLaw:
                return forceAs<BondLawKind::PowerLaw>(eta, p);
            case BondLawKind::Elastoplastic:
                return forceAs<BondLawKind::Elastoplastic>(eta, p);
        }
        return 0.0;
    }

    /// Psi(eta): the bond's stored (recoverable) energy.
    double energy(double eta, const PlasticState& p = {}) const {
        switch (kind) {
            case BondLawKind::Linear:
                return 0.5 * c * eta * eta;  // eq. 12
            case BondLawKind::PowerLaw: {
                const double held = std::max(eta, kMostCompression);
                const double s = 1.0 + held;  // eq. 13
                return powerC * (s * s + 1.0 / (s * s) - 2.0) +
                       powerCStar * (power(s, powerN) - 1.0 - powerN * held) +
                       (eta - held) * forceAs<BondLawKind::PowerLaw>(held);
            }
            case BondLawKind::Elastoplastic: {
                const double e = eta - plasticStrain(p);  // eq. 14's recoverable part
                return 0.5 * c * e * e;
            }
        }
        return 0.0;
    }

    /// Records the strain a bond has reached: the only irreversible part of eq. 20.
    PlasticState yieldStep(double eta, PlasticState p) const {
        if (kind == BondLawKind::Elastoplastic) p.maxStrain = std::max(p.maxStrain, eta);
        return p;
    }
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
