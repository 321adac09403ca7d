#pragma once
// VALIDATION.md, "momentum / energy, no damping, no fracture: conserved; drift < 1e-3 over 1e5
// steps at 0.8 dt_crit (Verlet)", and momentum to 1e-12 relative.
//
// A free sheet of ~500 particles (no boundaries, no damping, no fracture, no gravity) starts at
// rest shape with seeded random velocities in all three directions, of zero mean, and runs at
// dt = safety * stableTimeStep(). Total energy is kineticEnergy() + strainEnergy().
//
// Which figure is the "drift": with random velocities every lattice mode is excited, and at
// 0.8 of the Silling-Askari bound the highest in-plane mode has omega dt = 0.8 * sqrt(2) = 1.13
// (the bound is the Gershgorin estimate, 1/sqrt(2) of the true limit 2/omega_max on the
// hexagonal lattice). A symplectic scheme conserves a modified energy H + O(dt^p): the energy
// settles within a few hundred steps at a constant offset from E0 (the start, at rest shape, is
// not a typical point of the orbit) and oscillates about it with no secular growth. So the drift
// is the least-squares slope of E(t)/E0 after the settling steps, times the length of the run;
// the offset and the largest |E - E0|/E0 are what separates the two integrators.

#include "sim/Params.h"

namespace rend::checks {

struct FreeSheet {
    sim::Integrator integrator = sim::Integrator::VelocityVerlet;
    double safety = 0.8;  ///< dt over the stable bound
    long steps = 100000;
    long settle = 1000;  ///< steps left out of the fit
    long every = 10;     ///< steps between energy samples
};

struct EnergyRun {
    double drift;     ///< fitted slope of E/E0 over steps settle+1..end, times the run's steps
    double offset;    ///< mean of E/E0 - 1 over steps settle+1..end
    double worst;     ///< max over samples of |E - E0| / E0
    double momentum;  ///< |P(end) - P(0)| / sum m |v| at the start
    int particles;
    double dt, stableDt;
};

EnergyRun runFreeSheet(const FreeSheet& s);

/// The free sheet's stable bound [s]: it depends on the lattice alone, not on the integrator.
double freeSheetStableStep();

}  // namespace rend::checks
