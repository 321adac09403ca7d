#pragma once
// VALIDATION.md, patch test: "edge softening reported and corrected to <= 3%".
//
// The skin effect is measured where a user meets it: a narrow strip pulled along its length.
// A continuum strip of width W carries F = E W h e at strain e whatever W is; a particle strip
// whose edge particles miss bonds carries less, E_strip = E (1 - 2 d / N) for N cells across,
// where d is the stiffness the outermost row lacks, in cells. Each particle owns a cell of area
// dx * rowSpacing (the lattice's convention: its mass is rho h times that), so W = N cells.
//
// The strip is solved statically: sliding grips at both ends impose u_x = e x (u_y free), the
// rest is relaxed by conjugate gradients on the real force loop (Membrane::computeForces, linear
// at strain 1e-6), then E_strip = reaction / (h W e_mid) with e_mid fitted over the middle half,
// away from the grips. The outermost row's modulus 1 - d is read from two widths.

#include <string>

#include "sim/Membrane.h"

namespace rend::checks {

constexpr double kStripModulus = 2e4;  ///< E of the strips [Pa]

struct Strip {
    bool alongX = true;  ///< hexagonal rows are straight along x and zig-zag along y
    int cells = 8;       ///< N across the strip
    double horizonFactor = 1.5;
    bool surfaceCorrection = false;
    double dx = 0.01;
};

sim::MembraneParams stripParams(const Strip& s);

/// E_strip / E of the strip under uniaxial stress along its length.
double stripModulus(const Strip& s);

struct SkinFigures {
    double strip;     ///< E_strip / E at N = 5 R / dx cells
    double outerRow;  ///< 1 - d: the outermost row's modulus, from N and 2N
    double interior;  ///< E_inf / E
};

SkinFigures skin(bool alongX, double horizonFactor, bool corrected);

/// Issue 15's bimaterial strip: the strip (20 cells, R = 1.5 dx, surface-corrected for the
/// peridynamic bonds) of `solver` with an E
/// map making its half x > 0 `softFactor` times as stiff, pulled by its grips. In series both
/// halves carry the same stress, so each half's strain is stress / its E (the closed form):
/// the figures are each half's measured modulus over its own, 1 when the map is exact.
struct BimaterialFigures {
    double stiff;  ///< E measured in x < 0 over E
    double soft;   ///< E measured in x > 0 over softFactor E
};
BimaterialFigures bimaterialStrip(double softFactor, const std::string& solver = "peridynamic");

}  // namespace rend::checks
