#pragma once
// Issue 15's validation of the MPM solver (sim/Mpm.h) beside the others: the dynamic checks its
// grid transfer could fail (the statics are the FEM's lattice forces), shared by
// tests/validation/mpm_test.cpp and bench_accuracy's "mpm" case.

#include <string>

#include "sim/Params.h"

namespace rend::checks {

/// VALIDATION.md's wave arrival for any solver: the left edge of a wide sheet (E = 2e4 Pa,
/// rho = 5000 kg/m^3, nu as given; the bonds' is 1/3) driven in x by a velocity ramped over
/// 10 horizons' travel time; the front's speed between two probe lines over
/// c_p = sqrt(E / (rho (1 - nu^2))).
struct WaveFigures {
    double speedOverCp;
    int particles;
};
WaveFigures planeWave(const std::string& solver, double dx, double nu = 1.0 / 3.0,
                      const sim::MpmParams& mpm = {});

/// The bimaterial strip pulled in time (scenes/bimaterial_strip.toml's set-up: 1.6 x 0.3 m at
/// spacing dx, the half x > 0 at a quarter of E, the left edge pinned, the right pulled at
/// 0.04 m/s), against the FEM's run of the same. Quasi-static: a 1 s ramp, damping 4/s, to
/// t = 5 s. Dynamic (`jerk`): a 0.05 s ramp, no damping, to t = 1 s, while the waves cross the
/// interface.
struct PullFigures {
    double worstDifference;  ///< max over particles |u - u_fem| / max |u_fem|
    double softOverStiff;    ///< the halves' mean strains' ratio (the closed form: 4)
    int enriched;            ///< particles solved on their own domains at the end
    int particles;
};
PullFigures pulledBimaterial(const std::string& solver, double dx, const sim::MpmParams& mpm = {},
                             bool jerk = false);
/// Seed 002's Fig. 3 on the same strip: soft stripes (E / 10) `stripe` wide across it every
/// 2 stripes, so one grid cell of mpm.grid dx >= stripe holds both materials; pulled with the
/// jerk, against the FEM's run.
PullFigures pulledStripes(double dx, double stripe, const sim::MpmParams& mpm);

/// A free square sheet (0.4 m, dx 0.02) spun about its normal at 1 rad/s (a centrifugal strain
/// of about 1%), no gravity or damping, for `steps` steps at half the stable step: the relative
/// change of its angular momentum about its centre of mass. Seed 004's figure (its Sec. 5.4, a
/// spinning disc) with `disc`: a disc of radius 0.2 m spun at 3.16 rad/s (strain about 10%),
/// remeshed every `remeshEvery` steps (0: never).
struct SpinFigures {
    double angularMomentumDrift;  ///< |L_end - L_0| / |L_0|
    double kineticEnergyRatio;    ///< KE_end / KE_0
};
SpinFigures spinningSheet(const std::string& solver, int steps, const sim::MpmParams& mpm = {},
                          bool disc = false, int remeshEvery = 0);

/// Collision through the grid against the contact of the other solvers: a sheet (0.2 x 0.4 m,
/// dx 0.02) cut across y = 0, its upper half laid 4 cm over its lower half on the ground and
/// dropped under gravity, damping 2/s, for 0.8 s.
struct StackFigures {
    double meanGap;      ///< the upper piece's mean height over the lower's [m] at the end
    double closestPair;  ///< the closest approach of two particles not bonded at rest [m]
    double seconds;      ///< wall time of the run
    int below;           ///< upper particles that ended below the lower piece's mean height
};
StackFigures droppedOnItself(const std::string& solver, bool selfContact,
                             const sim::MpmParams& mpm = {});

}  // namespace rend::checks
