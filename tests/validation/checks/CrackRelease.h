#pragma once
// VALIDATION.md "fracture energy" for every solver: the pulled, long-notched strip of
// checks/FractureEnergy.h, booked without looking inside the solver. At every step the strain
// energy released by the breaking itself is
//     U(x_n, state before the step) - U(x_n, state after it),
// Solver::strainEnergy at the same positions x_n with the broken pieces in and out. It is exact
// because Membrane::step() breaks at x_n: symplectic Euler (the default) calls Solver::advance
// at x_n, and every advance() breaks before it computes the forces there. It is zero, bit for
// bit, in a step where nothing breaks (the same serial sum over the same state). With the
// peridynamic bonds it is the energy each broken bond held at its stretch at x_n, a little past
// eta_c, so it must come out a little above runCrack's booking at eta_c.
//
// The crack's geometry comes from the Membrane's bonds, which every solver's broken edges break
// (at R = 1.5 dx the bonds are the lattice's edges): the FEM reports a side only once both
// elements on it are gone, SPH only the pairs that are lattice edges.

#include <cstddef>
#include <limits>

#include "tests/validation/checks/FractureEnergy.h"

namespace rend::checks {

struct ReleaseRecord {
    double released = 0.0;  ///< J, over the steps that broke nothing at the grips
    /// J released in steps that broke something farther than H/4 from the notch's line.
    double elsewhereReleased = 0.0;
    double negativeReleased = 0.0;  ///< J, the sum of the steps whose release was below zero
    double windowReleased = 0.0;    ///< J, released while the front was inside the window
    double windowFrom = 0.0;        ///< the front when it entered the window
    double windowTo = 0.0;          ///< the front when it left it (or the run ended)
    double front = -1e9;            ///< largest midpoint x of a broken bond on the notch's line
    double notchFront = -1e9;       ///< the same for the notch's bonds
    std::size_t broken = 0;         ///< bonds broken within H/4 of the notch's line
    std::size_t offLine = 0;        ///< of those, bonds that do not cross the line
    std::size_t elsewhere = 0;      ///< bonds broken farther than H/4 from it (at the grips)
    long breakingSteps = 0;         ///< steps that released energy
    double strainAtStart = 0.0;     ///< grip strain at the first release, over Griffith's
    /// Smallest stretch at x_n of a bond broken in step n, over the solver's critical strain
    /// (`critical`): >= 1 shows the bond broke at x_n. For the bonds and springs only.
    double minBreakStretch = std::numeric_limits<double>::infinity();
    double critical = std::numeric_limits<double>::infinity();
    /// Mean over the bonds broken on the line of (stretch at x_n / critical)^2: what the release
    /// books over a booking at the critical strain, for the bonds and the Van Gelder springs
    /// (one energy per bond, all alike along a row); 0 for the others.
    double overshoot = 0.0;
    double seconds = 0.0;  ///< simulated time when the crack reached the end of the window
    bool reached = false;
};

/// Pulls the strip (any solver) until the crack front passes `windowEnd`, booking the energy each
/// step's breaking releases.
ReleaseRecord runCrackRelease(const NotchedStrip& s, double windowStart, double windowEnd);

/// Released energy per unit new crack length and thickness over G_f: over the whole crack, or
/// (`window`) only while the front crossed the window, free of the start-up transient.
double releasedPerLength(const NotchedStrip& s, const ReleaseRecord& r, bool window = false);

}  // namespace rend::checks
