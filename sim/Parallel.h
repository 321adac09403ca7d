#pragma once

#include <omp.h>

namespace rend::sim {

/// Below this many particles a loop over particles runs serially: waking the OpenMP team costs
/// more than it saves. The loop body is the same either way, so results do not change.
inline constexpr int kParallelThreshold = 2048;

/// Whether a loop that is `wide` enough (its kParallelThreshold test) wakes the OpenMP team:
/// only where more than one thread would run it. Else it runs on the calling thread, outside
/// any parallel region: libgomp ends even a team of one (an `if` clause that is false makes one
/// too) with a futex wake, a system call of 2-3 us on a 2-core VM, and the three regions of a
/// crack_path_sources step on one thread were 0.6 ns per particle-step at 10^4 particles.
inline bool wakesTeam(bool wide) { return wide && omp_get_max_threads() > 1; }

/// body(i) for i in [begin, end): by the team, statically scheduled, where wakesTeam(wide),
/// else in order on this thread.
template <class Body>
void forEachIndex(bool wide, int begin, int end, Body&& body) {
    if (wakesTeam(wide)) {
#pragma omp parallel for schedule(static)
        for (int i = begin; i < end; ++i) body(i);
        return;
    }
    for (int i = begin; i < end; ++i) body(i);
}

/// The largest of `most` and what body(i, largest) leaves in `largest` for i in [begin, end),
/// as forEachIndex runs them: by the team, each thread's `largest` its own (OpenMP's max
/// reduction), or on this thread with `most` itself. A maximum: the same for any thread count.
template <class Body>
double largestOverIndices(bool wide, int begin, int end, double most, Body&& body) {
    if (wakesTeam(wide)) {
#pragma omp parallel for schedule(static) reduction(max : most)
        for (int i = begin; i < end; ++i) body(i, most);
        return most;
    }
    for (int i = begin; i < end; ++i) body(i, most);
    return most;
}

/// body() on each thread of the team where wakesTeam(wide), else once on this thread (where
/// omp_get_num_threads() is 1 and omp_get_thread_num() 0, and a barrier returns at once).
template <class Body>
void inTeam(bool wide, Body&& body) {
    if (wakesTeam(wide)) {
#pragma omp parallel
        body();
        return;
    }
    body();
}

/// inTeam with a maximum: each thread's body(largest) starts from its own copy (OpenMP's max
/// reduction), or body(most) on this thread; the largest of `most` and theirs.
template <class Body>
double largestInTeam(bool wide, double most, Body&& body) {
    if (wakesTeam(wide)) {
#pragma omp parallel reduction(max : most)
        body(most);
        return most;
    }
    body(most);
    return most;
}

}  // namespace rend::sim
