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

namespace rend {

/// The busy CPU seconds of all cores, summed, from /proc/stat's first line ("cpu  user nice
/// system idle iowait irq softirq steal ..." in ticks): user + nice + system + irq + softirq.
/// -1 when the line does not parse.
double busySecondsFromProcStat(std::string_view procStat, double ticksPerSecond);

/// The threads that fit beside other processes that keep `otherCores` cores busy: usable less
/// those (rounded), at least 1.
int threadsBeside(int usable, double otherCores);

/// A thread count that follows the machine's load (issue 16): on a machine another job shares,
/// threads beyond the free cores only wait for each other at every barrier (measured: 2 threads
/// beside one busy process ran 1.1-3.6x slower than 1). Called at every frame; at most every
/// kWindowSeconds it measures the cores other processes kept busy since its last look (the
/// machine's busy time in /proc/stat less this process's CPU time, over the wall time) and sets
/// OpenMP's count to the usable cores they leave. A short-lived task hardly moves it. Results
/// do not change: every loop gives the same bits for any thread count.
class ThreadGovernor {
public:
    static constexpr double kWindowSeconds = 0.25;
    explicit ThreadGovernor(int usable) : usable_(usable), threads_(usable) {}
    /// Looks at the machine when the window has passed and sets omp_set_num_threads; returns
    /// the count.
    int atFrame();
    int threads() const { return threads_; }

private:
    int usable_, threads_;
    bool started_ = false;
    double wall_ = 0.0, busy_ = 0.0, own_ = 0.0;  ///< at the last look [s]
};

}  // namespace rend
