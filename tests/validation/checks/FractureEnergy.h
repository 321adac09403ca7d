#pragma once
// VALIDATION.md, "fracture energy: energy of broken bonds per unit new crack length = G_f, within
// 10%". A long-notched strip (the "pure shear" geometry: once the notch is longer than the strip
// is high, the energy release rate E' eps^2 H / 2 no longer depends on the crack length, so the
// crack runs steadily) is pre-stretched to 0.8 of the strip's Griffith strain, then pulled slowly
// at its top and bottom edges, with heavy damping so the crack runs quasi-statically. Every bond
// that breaks is booked with the energy it held at breaking, U = W0 V_i V_j c eta_c^2 / 2
// (BondLaw.h), and the total is divided by the new crack length and the thickness.
//
// What to expect on the hexagonal lattice (sim/Fracture.h): the calibration averages the bonds
// crossing a crack over all directions. A crack along a lattice row cuts the bonds of a particle
// in proportion to sum_j W0_j |xi_j . n| instead of the average (2/pi) sum_j W0_j |xi_j|, so it
// stores their ratio times G_f (rowCrackShare). At R = 1.5 dx that is two bonds per dx instead of
// the average 2.31: pi sqrt(3)/6 = 0.907 G_f, whatever dx is.
//
// The crack starts only near 1.8 x the strip's Griffith strain (3.2 G_f, see griffith_test.cpp),
// so it runs with energy to spare: with light damping (2/s) it branches into a band several rows
// wide and the booked energy reaches 2.4 G_f. Damping 60/s keeps it to one row.

#include <cstddef>

#include "sim/Membrane.h"

namespace rend::checks {

/// A 1.2 m x 0.3 m strip, notched from the left edge along the line between the two rows next
/// to y = 0 up to x = -0.25 m (0.35 m, longer than the strip is high).
struct NotchedStrip {
    /// Any solver; the others than the peridynamic bonds get nu = 1/3, the bonds' own, so the
    /// strip's Griffith strain is the same for all (checks/CrackRelease.h books them).
    std::string solver = "peridynamic";
    sim::CriticalStretchMode mode = sim::CriticalStretchMode::Calibrated;
    double dx = 0.01;  ///< m
    double horizonFactor = 1.5;
    double youngsModulus = 2e4;   ///< Pa
    double density = 5000;        ///< kg/m^3
    double thickness = 1e-3;      ///< m
    double fractureEnergy = 0.5;  ///< J/m^2: eta_c = 0.051 (calibrated, R = 1.5 dx)
    double width = 1.2, height = 0.3;
    double notchTip = -0.25;
    double strainRate = 0.01;     ///< 1/s, after the pre-stretch
    double damping = 60.0;        ///< 1/s
    double duration = 6.0;        ///< s, simulated, at most
    double timeStepSafety = 0.8;  ///< dt over the stable bound (TimeParams::safety)
    /// Tries a recalibration without touching the solver: its critical strain, proportional to
    /// sqrt(G_f) in every solver, is scaled by this, the material getting G_f scale^2, while the
    /// booking and the Griffith strain keep fractureEnergy.
    double criticalStrainScale = 1.0;
    /// Hold the far (right) end in the strip's uniform plane-strain state. Left free, the
    /// corners where it meets the grips concentrate stress and break (the `elsewhere` bonds): at
    /// dx = 0.01, 58 bonds at R = 2 dx while the crack runs, and at R = 3 dx 1592, starting
    /// before the crack and stopping it short of the window.
    bool holdFarEnd = false;
};

struct CrackRecord {
    double energy = 0.0;          ///< sum of W0 V_i V_j c eta_c^2 / 2 over the bonds broken
    double crossingEnergy = 0.0;  ///< the part of it in bonds that cross the notch's line
    double front = -1e9;          ///< largest midpoint x of a broken bond
    double notchFront = -1e9;     ///< the same for the notch's bonds
    double windowEnergy = 0.0;
    std::size_t broken = 0;
    std::size_t offLine = 0;     ///< broken bonds that do not cross the notch's line
    std::size_t elsewhere = 0;   ///< broken bonds farther than H/4 from it (at the grips)
    double strainAtStart = 0.0;  ///< grip strain when the first bond broke, over Griffith's
    double etaC = 0.0;
    double seconds = 0.0;  ///< simulated time when the crack reached the end of the window
    bool reached = false;
    double rowShare = 0.0;  ///< rowCrackShare of this strip's lattice
};

sim::MembraneParams pulledStrip(const NotchedStrip& s);

/// The strip's Griffith strain, E' eps^2 H / 2 = G_f with E' = E / (1 - nu^2), nu = 1/3 (the
/// grips hold x), H the distance between the grip rows of `p` = pulledStrip(s).
double stripGriffithStrain(const NotchedStrip& s, const sim::MembraneParams& p);

/// Pulls the strip until the crack front passes `windowEnd`, booking every bond as it breaks;
/// the window [windowStart, windowEnd) books its own energy too.
CrackRecord runCrack(const NotchedStrip& s, double windowStart, double windowEnd);

/// Booked energy per unit new crack length and thickness, over G_f; only that of the bonds
/// crossing the notch's line when `crossingOnly`.
double energyPerLength(const NotchedStrip& s, const CrackRecord& r, bool crossingOnly = false);

/// What a straight crack along a lattice row (normal y) stores with the calibrated eta_c, over
/// G_f: sum_j W0_j |xi_j,y| / ((2/pi) sum_j W0_j |xi_j|) over the family of an interior particle.
double rowCrackShare(const sim::Membrane& m);

}  // namespace rend::checks
