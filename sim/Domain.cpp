#include "sim/Domain.h"

#include <algorithm>
#include <string>

namespace rend::sim {

std::vector<Slab> partitionSlabs(const BondFamilies& bonds, int count) {
    const int n = bonds.particleCount();
    std::vector<Slab> slabs(count);
    for (int r = 0; r < count; ++r) {
        Slab& s = slabs[r];
        s.begin = int(std::int64_t(n) * r / count);
        s.end = int(std::int64_t(n) * (r + 1) / count);
        // Pairs are computed from their smaller index: those of the owned particles' partners
        // below the slab too, so the ghosts reach the partners of those.
        s.ghostBegin = s.begin;
        for (int i = s.begin; i < s.end; ++i)
            if (bonds.offsets[i] < bonds.offsets[i + 1])
                s.ghostBegin = std::min(s.ghostBegin, bonds.partners[bonds.offsets[i]]);
        s.ghostEnd = s.end;
        for (int i = s.ghostBegin; i < s.end; ++i)
            if (bonds.offsets[i] < bonds.offsets[i + 1])
                s.ghostEnd = std::max(s.ghostEnd, bonds.partners[bonds.offsets[i + 1] - 1] + 1);
    }
    for (int r = 0; r < count; ++r) {
        const Slab& s = slabs[r];
        const bool below = r == 0 || s.ghostBegin >= slabs[r - 1].begin;
        const bool above = r + 1 == count || s.ghostEnd <= slabs[r + 1].end;
        if (s.begin == s.end || !below || !above)
            throw std::invalid_argument(
                std::to_string(count) + " processes cut the sheet's " + std::to_string(n) +
                " particles into slabs thinner than its bonds reach: run with fewer processes");
    }
    return slabs;
}

}  // namespace rend::sim
