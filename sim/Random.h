#pragma once
#include <cstdint>

namespace rend::sim {

/// Uniform [0, 1) from (seed, index) through splitmix64 (Steele, Lea & Flood 2014): a value per
/// item that does not depend on how many items came before it or on the thread count.
inline double uniformFromHash(std::uint64_t seed, std::uint64_t index) {
    std::uint64_t z = seed + 0x9e3779b97f4a7c15ULL * (index + 1);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return double(z >> 11) * 0x1.0p-53;
}

}  // namespace rend::sim
