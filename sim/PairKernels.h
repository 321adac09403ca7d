#pragma once
// The vectorised first pass of the linear law's force loop (eq. 18 with eqs. 10, 27-28 and the
// diffusion's strain and weakening): each pair's force on its smaller index, from structure-of-
// arrays inputs, for a range of pairs. sim/PeridynamicBonds.cpp gathers the pair forces per
// particle. Four pairs at a time with AVX2 where the CPU has it, else one at a time; both use
// only +, -, *, / and sqrt (no fused multiply-add), so their bits are the same.

#include <cstdint>

namespace rend::sim {

struct LinearPairInput {
    const int* first = nullptr;   ///< per pair: the smaller index i
    const int* second = nullptr;  ///< per pair: j
    const double* restLength = nullptr;
    const double* scale = nullptr;  ///< the bond scale (sim/BondLaw.h)
    const double* limit = nullptr;  ///< eta_c times the map's factor; null: unbreakable
    const double* x = nullptr;      ///< positions, x y z per particle
    const double* theta = nullptr;  ///< null: no diffusion
    double c = 0.0;                 ///< micromodulus
    double expansion = 0.0;         ///< alpha
    double stiffnessLoss = 0.0;     ///< of sim/Material.h's degradation()
    double strengthLoss = 0.0;
};

struct LinearPairOutput {
    double* fx = nullptr;  ///< per pair: its force on i; zero where it is past its limit
    double* fy = nullptr;
    double* fz = nullptr;
    std::uint8_t* over = nullptr;  ///< per pair: past its limit (only with a limit)
};

/// Pairs [begin, end). Dead bonds are computed too: the gather skips them.
void linearPairForces(const LinearPairInput& in, const LinearPairOutput& out, int begin, int end);

}  // namespace rend::sim
