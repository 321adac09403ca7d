#pragma once

namespace rend::sim {

/// Below this many particles a loop over particles runs serially: waking the OpenMP team costs
/// more than it saves. The loop body is the same either way, so results do not change.
inline constexpr int kParallelThreshold = 2048;

}  // namespace rend::sim
