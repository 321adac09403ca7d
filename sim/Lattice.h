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

/// Geodesic sphere: the icosahedron subdivided n times, n the least with edges <= ~dx.
Lattice generateSphere(const SheetParams& sheet);

/// Number of particles generateLattice would produce, without allocating them.
std::size_t estimateParticleCount(const SheetParams& sheet);

}  // namespace rend::sim
