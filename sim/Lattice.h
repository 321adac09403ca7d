#pragma once
// Rest lattice of a membrane: one layer of uniformly spaced particles filling the outline.

#include <Eigen/Core>
#include <array>
#include <vector>

#include "sim/Params.h"

namespace rend::sim {

struct Lattice {
    std::vector<Eigen::Vector3d> positions;     ///< rest positions, row by row
    std::vector<std::array<int, 3>> triangles;  ///< counter-clockwise seen from +z
    double particleArea = 0.0;                  ///< area per particle (Voronoi cell)
    /// Per-particle areas where they differ (the sphere: a third of the incident triangles);
    /// empty for the flat lattices, whose cells are all particleArea.
    std::vector<double> areas;
};

/// Square lattice: cells dx^2. Hexagonal: rows dx*sqrt(3)/2 apart, odd rows shifted by dx/2,
/// cells dx^2*sqrt(3)/2. Both are centred on the sheet so the lattice is mirror-symmetric.
Lattice generateLattice(const SheetParams& sheet);

/// Seed 004's ghost particles for a flat sheet (issue 15): the sheet's lattice continued past
/// its outline. The ghost sites are the grid points outside the outline that share a triangle
/// of the continued lattice with a particle; the band's triangles are the continued lattice's
/// triangles with both a particle and a ghost corner, counter-clockwise from +z, a particle
/// numbered as generateLattice numbers it and ghost k as particleCount + k. Empty for a sphere,
/// which has no outline.
struct GhostBand {
    std::vector<Eigen::Vector3d> sites;
    std::vector<std::array<int, 3>> triangles;
};
GhostBand ghostBand(const SheetParams& sheet);

/// Signed distance in the rest plane from p to the sheet's outline: negative inside. A sphere
/// has no outline: -infinity.
double outlineDistance(const SheetParams& sheet, const Eigen::Vector3d& p);

/// Geodesic sphere: the icosahedron subdivided n times, n the least with edges <= ~dx.
Lattice generateSphere(const SheetParams& sheet);

/// Number of particles generateLattice would produce, without allocating them.
std::size_t estimateParticleCount(const SheetParams& sheet);

/// The coarsest spacing, to three significant digits, at which the sheet holds at least
/// `target` particles (`sheet.dx` is ignored): how `quality = "final"` picks its dx.
double spacingForParticles(SheetParams sheet, std::size_t target);

/// The seeded out-of-plane jitter at rest of each particle at `positions`, in metres. Its random
/// values sit on the lattice of spacing `sheet.seedSpacing` (one per particle there) and are
/// interpolated linearly in between, so a finer lattice of the same sheet samples the same
/// surface instead of drawing a rougher one.
std::vector<double> perturbationHeights(const SheetParams& sheet,
                                        const std::vector<Eigen::Vector3d>& positions);

/// The lattice of spacing `sheet.seedSpacing` (0: dx), on which seeded placements (scattered
/// spots) are drawn and sources are measured, so they stay the same at every spacing.
Lattice seedLattice(const SheetParams& sheet);

}  // namespace rend::sim
