#pragma once
// Eight values of a row of a vectorised kernel (the k-th bonds of a tile's particles side by
// side) as the row's smallest plus whole steps (0-65535) of the smallest's last bit: where a
// lattice's coordinates carry rounding, the bonds of one direction differ only in their last
// bits, and a kernel reads two bytes per value where it read eight, with the same bits
// (sim/PairKernels.h's classes, sim/DiffusionKernels.h's rates).

#include <cstdint>
#include <optional>

namespace rend::sim {

struct RowSteps {
    double smallest = 0.0, unit = 0.0;
    bool stepped = false;  ///< some value is not the smallest
};

/// The row of eight values, each checked to give its own bits as smallest + steps[k] * unit
/// (the kernels' expression); nothing where one does not (NaN, values far apart).
std::optional<RowSteps> rowSteps(const double* values, std::uint16_t* steps);

}  // namespace rend::sim
