#pragma once
// The scene's material as one value, validated once, that every solver reads: the elastic
// constants (with the plane-stress Lame constants of the continuum solvers), the bond law and
// its parameters, and the couplings to the diffusing theta (thermal strain, stiffness and
// strength loss). The physics each solver shares is written here once.

#include <algorithm>

#include "sim/BondLaw.h"
#include "sim/Params.h"

namespace rend::sim {

/// Degradation by the diffusive quantity (acid, moisture): stiffness or critical strain scale
/// by max(0, 1 - loss * theta).
inline double degradation(double loss, double theta) { return std::max(0.0, 1.0 - loss * theta); }

/// The power law's look-ahead strain is held at BondLaw::kMostCompression (a bond squashed to
/// 5%, where its force is held too) before its stiffening sets the sub-steps, whatever the solver.
inline double clampCompression(double strain) {
    return std::max(strain, BondLaw::kMostCompression);
}

class Material {
public:
    /// Throws std::invalid_argument unless E > 0 and -1 < nu < 1/2 (lambda* and mu
    /// below are finite and positive only there). Implicit, so a solver built in a test from
    /// MaterialParams checks them too.
    Material(const MaterialParams& params);  // NOLINT(google-explicit-constructor)

    const MaterialParams& params() const { return params_; }
    double youngsModulus() const { return params_.youngsModulus; }
    double poissonRatio() const { return params_.poissonRatio; }

    /// Plane-stress Lame constants lambda* = E nu / (1 - nu^2) and mu = E / (2 (1 + nu)).
    double lambda() const { return lambda_; }
    double mu() const { return mu_; }

    /// The bond law (eqs. 18-20) at micromodulus c; c = 1 gives its shape f/c.
    BondLaw law(double c) const { return BondLaw::fromMaterial(params_, c); }

    /// alpha: the thermal strain per unit theta.
    double expansion() const { return params_.expansion; }
    /// The factor on the stiffness and on the critical strain at theta.
    double stiffnessFactor(double theta) const { return degradation(params_.stiffnessLoss, theta); }
    double strengthFactor(double theta) const { return degradation(params_.strengthLoss, theta); }

private:
    MaterialParams params_;
    double lambda_ = 0.0, mu_ = 0.0;
};

}  // namespace rend::sim
