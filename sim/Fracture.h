#pragma once
// Fracture of the membrane paper (Section 5, eqs. 27-28): a bond whose mechanical strain
// exceeds the critical stretch eta_c breaks for good; it then carries neither force nor
// diffusion. Pre-notches break the bonds they cross at set-up.
//
// Calibrated critical stretch. A straight crack separates every bond that crosses it. For a
// line of normal n through the lattice, averaging over the line's offset, the bonds of a
// particle crossing a unit length number sum_j |xi_j . n| / (2 A); averaged over directions
// |xi . n| -> (2/pi) |xi|. A bond at eta_c stores W0 V_i V_j c eta_c^2 / 2, so the energy per unit
// crack length and unit thickness is
//     G = c eta_c^2 / (2 pi) * sum_j W0_j |xi_j| V_j,
// and eta_c = sqrt(2 pi G_f / (c S)), S the sum of an interior particle. In the continuum,
// S = pi h R^3 / 6 and c = 18E/(pi h R^2) give eta_c = sqrt(2 pi G_f / (3 E R)): sqrt(3/2) times
// eq. 28's sqrt(4 pi G_f / (9 E R)), which belongs to the constant-influence bond of Silling's
// PMB, not to this one. Eq. 28 as printed is kept as an option.

#include <Eigen/Core>
#include <span>
#include <vector>

#include "sim/Bonds.h"
#include "sim/Params.h"

namespace rend::sim {

/// eta_c = sqrt(2 pi G_f / (c S)) with S = sum_j W0_j |xi_j| V_j of an interior particle.
double calibratedCriticalStretch(double fractureEnergy, double micromodulus,
                                 double interiorWeightedMoment);

/// Eq. 28 as printed: eta_c = sqrt(4 pi G_f / (9 E R)).
double paperCriticalStretch(double fractureEnergy, double youngsModulus, double horizon);

/// params with critical_stretch = "preview" or "midway" resolved: every solver's critical strain
/// goes as sqrt(G_f / dx) at a fixed horizon factor, so G_f dx / dx_preview breaks this spacing's
/// bonds at the preview's strain, and G_f sqrt(dx / dx_preview) at the geometric mean of that
/// and the calibrated strain. Unchanged in the other modes, or at the preview spacing.
MembraneParams withPreviewStrength(MembraneParams params);

/// params with the elastoplastic softening (eq. 20's beta) given at the preview spacing held to
/// the same energy per unit crack area at this one (a crack band, Bazant and Oh 1983): a
/// softening law localises its strain in one row of bonds, whose work past the yield,
/// eta0^2 / beta for each bond, must then grow as 1 / dx, so beta scales with dx / dx_preview.
/// Unchanged for the other laws, or at the preview spacing.
MembraneParams withCrackBandSoftening(MembraneParams params);

/// Critical strain of the spring and FEM solvers: the springs crossing a unit crack along a
/// lattice row store the fracture energy G_f (infinity without one).
double springCriticalStrain(const MembraneParams& params);

/// Critical strain of the FEM elements and the two-parameter springs, whose cracks take out a
/// band of elements (triangles) one row high: sqrt(2 (1 - nu^2)) times the springs'.
double bandCriticalStrain(const MembraneParams& params);

/// Whether segments pq and ab cross. A point exactly on the other segment's line counts as on
/// its left, so a notch along a lattice row cuts the bonds below that row and no others.
bool segmentsCross(const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& a,
                   const Eigen::Vector2d& b);

/// Both copies of every bond whose rest segment crosses a notch, in index order.
std::vector<int> notchedBonds(std::span<const Notch> notches, std::span<const Eigen::Vector3d> rest,
                              const BondFamilies& bonds);

}  // namespace rend::sim
