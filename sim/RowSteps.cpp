#include "sim/RowSteps.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

namespace rend::sim {

std::optional<RowSteps> rowSteps(const double* values, std::uint16_t* steps) {
    constexpr int kRow = 8;
    RowSteps r{*std::min_element(values, values + kRow), 0.0, false};
    if (std::isfinite(r.smallest) && r.smallest != 0.0)
        r.unit = std::ldexp(1.0, std::ilogb(r.smallest) - std::numeric_limits<double>::digits + 1);
    std::uint16_t found[kRow];
    for (int k = 0; k < kRow; ++k) {
        if (std::bit_cast<std::uint64_t>(values[k]) == std::bit_cast<std::uint64_t>(r.smallest)) {
            found[k] = 0;
            continue;
        }
        const double count = r.unit > 0.0 ? std::round((values[k] - r.smallest) / r.unit) : -1.0;
        if (!(count >= 1.0 && count <= 65535.0)) return std::nullopt;
        const double back = r.smallest + count * r.unit;  // the kernels' (exact product)
        if (std::bit_cast<std::uint64_t>(back) != std::bit_cast<std::uint64_t>(values[k]))
            return std::nullopt;
        found[k] = std::uint16_t(count), r.stepped = true;
    }
    std::copy(found, found + kRow, steps);
    return r;
}

}  // namespace rend::sim
