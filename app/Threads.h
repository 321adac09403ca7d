#pragma once
// The default thread count (issue 16): the cores this process may really use. OpenMP's own
// default counts the CPUs of the affinity mask; a container's CPU quota (cgroup) can grant far
// fewer, and threads beyond it wait on each other at every parallel loop's barrier.

#include <string_view>

namespace rend {

/// The cores a cgroup v2 `cpu.max` line grants ("QUOTA PERIOD", or "max PERIOD" for no limit):
/// ceil(QUOTA / PERIOD), at least 1; 0 when there is no limit or the line does not parse.
int coresFromCpuMax(std::string_view cpuMax);

/// The cores this process may use: the CPUs of its affinity mask, capped by its cgroup's CPU
/// quota (v2 `cpu.max`, else v1 `cpu.cfs_quota_us` over `cpu.cfs_period_us`).
int usableCores();

}  // namespace rend
