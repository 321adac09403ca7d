#pragma once
// Test access to the peridynamic bonds' own constants, which the Membrane does not carry:
// its solver, cast. Throws std::logic_error when the scene runs another solver.

#include <Eigen/Core>
#include <stdexcept>

#include "sim/Membrane.h"
#include "sim/PeridynamicBonds.h"

namespace rend::test {

inline const sim::PeridynamicBonds& bondsOf(const sim::Membrane& m) {
    const auto* bonds = dynamic_cast<const sim::PeridynamicBonds*>(&m.solver());
    if (!bonds) throw std::logic_error("the membrane's solver is not the peridynamic bonds");
    return *bonds;
}

/// The micromodulus c of eq. 18.
inline double micromodulus(const sim::Membrane& m) { return bondsOf(m).law().c; }

/// eta_c at theta = 0; +infinity without a fracture energy.
inline double criticalStretch(const sim::Membrane& m) { return bondsOf(m).criticalStretch(); }

/// Virial stress of particle i at the membrane's current state.
inline Eigen::Matrix3d particleStress(const sim::Membrane& m, int i) {
    return bondsOf(m).particleStress(i, m.stepState());
}

}  // namespace rend::test
