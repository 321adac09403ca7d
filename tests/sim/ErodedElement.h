#pragma once
// A FEM sheet with one interior element eroded while its three neighbours live on: its sides
// stay intact, so only the removal itself (DamageState::removeTriangle) can take it out of the
// pressure load and the surfaces.

#include <Eigen/Geometry>
#include <cmath>

#include "sim/Membrane.h"

namespace rend::test {

/// A 0.2 m FEM sheet that breaks (G_f = 5) under `pressure`.
inline sim::MembraneParams erodingSheet(double pressure) {
    sim::MembraneParams p;
    p.solver = "fem_cst";
    p.sheet.size = {0.2, 0.2};
    p.sheet.dx = 0.02;
    p.material.youngsModulus = 2e4;
    p.material.poissonRatio = 0.3;
    p.material.density = 5000;
    p.material.fractureEnergy = 5.0;
    p.pressure = pressure;
    p.time.dt = 1e-5;
    return p;
}

/// Moves a vertex of the triangle nearest the centre away from its opposite side, so that the
/// element's largest Green strain is 1.1 times the critical one and its neighbours' (which see
/// the move at 60 degrees or more, about 0.75 times as much) stay below it; then steps once.
/// Returns the triangle.
inline int erodeOneElement(sim::Membrane& m, const sim::MembraneParams& p) {
    const auto& triangles = m.lattice().triangles;
    const auto& x0 = m.restPositions();
    const auto centroid = [&](int t) {
        return (x0[triangles[t][0]] + x0[triangles[t][1]] + x0[triangles[t][2]]) / 3.0;
    };
    int t = 0;
    for (int k = 1; k < int(triangles.size()); ++k)
        if (centroid(k).norm() < centroid(t).norm()) t = k;
    const auto [a, b, c] = triangles[t];
    const Eigen::Vector3d side = (x0[c] - x0[b]).normalized();
    const Eigen::Vector3d foot = x0[b] + side * side.dot(x0[a] - x0[b]);
    const Eigen::Vector3d height = x0[a] - foot;  // h g, g the unit normal to side bc
    const double limit = sim::bandCriticalStrain(p);
    const double green = 1.1 * 0.5 * ((1.0 + limit) * (1.0 + limit) - 1.0);
    const double s = std::sqrt(1.0 + 2.0 * green) - 1.0;  // s + s^2 / 2 = green
    m.positions()[a] = x0[a] + s * height;
    m.step();
    return t;
}

}  // namespace rend::test
