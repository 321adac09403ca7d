#include "app/Threads.h"

#include <omp.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace rend {
namespace {

std::string firstLine(const char* path) {
    std::ifstream in(path);
    std::string line;
    std::getline(in, line);
    return line;
}

bool parseNumber(std::string_view text, double& value) {
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    return error == std::errc() && end == text.data() + text.size();
}

int coresFromQuota(double quota, double period) {
    if (!(quota > 0.0) || !(period > 0.0)) return 0;
    return std::max(1, int(std::ceil(quota / period - 1e-9)));
}

/// cgroup v1: cpu.cfs_quota_us is -1 without a limit.
int coresFromCfs() {
    double quota = 0.0, period = 0.0;
    if (!parseNumber(firstLine("/sys/fs/cgroup/cpu/cpu.cfs_quota_us"), quota) ||
        !parseNumber(firstLine("/sys/fs/cgroup/cpu/cpu.cfs_period_us"), period))
        return 0;
    return coresFromQuota(quota, period);
}

}  // namespace

int coresFromCpuMax(std::string_view cpuMax) {
    while (!cpuMax.empty() && (cpuMax.back() == '\n' || cpuMax.back() == ' '))
        cpuMax.remove_suffix(1);
    const std::size_t space = cpuMax.find(' ');
    if (space == std::string_view::npos) return 0;
    double quota = 0.0, period = 0.0;
    if (!parseNumber(cpuMax.substr(0, space), quota) ||
        !parseNumber(cpuMax.substr(space + 1), period))
        return 0;  // "max": no limit
    return coresFromQuota(quota, period);
}

int usableCores() {
    cpu_set_t set;
    int cores = 0;
    if (sched_getaffinity(0, sizeof set, &set) == 0) cores = CPU_COUNT(&set);
    if (cores <= 0) cores = std::max(1L, sysconf(_SC_NPROCESSORS_ONLN));
    int quota = coresFromCpuMax(firstLine("/sys/fs/cgroup/cpu.max"));
    if (quota == 0) quota = coresFromCfs();
    return quota > 0 ? std::min(cores, quota) : cores;
}

}  // namespace rend

namespace rend {

double busySecondsFromProcStat(std::string_view procStat, double ticksPerSecond) {
    if (procStat.substr(0, 4) != "cpu ") return -1.0;
    const char* p = procStat.data() + 4;
    const char* end = procStat.data() + procStat.find('\n');
    double fields[8] = {};  // user nice system idle iowait irq softirq steal
    for (double& field : fields) {
        while (p < end && *p == ' ') ++p;
        long long value = 0;
        const auto [next, error] = std::from_chars(p, end, value);
        if (error != std::errc()) return -1.0;
        field = double(value), p = next;
    }
    return (fields[0] + fields[1] + fields[2] + fields[5] + fields[6]) / ticksPerSecond;
}

int threadsBeside(int usable, double otherCores) {
    return std::clamp(usable - int(std::lround(std::max(0.0, otherCores))), 1, usable);
}

namespace {

std::string readSmallFile(const char* path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

double ownCpuSeconds() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    auto seconds = [](const timeval& t) { return double(t.tv_sec) + 1e-6 * double(t.tv_usec); };
    return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

}  // namespace

int ThreadGovernor::atFrame() {
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
    if (started_ && wall - wall_ < kWindowSeconds) return threads_;
    const double busy =
        busySecondsFromProcStat(readSmallFile("/proc/stat"), double(sysconf(_SC_CLK_TCK)));
    if (busy < 0.0) return threads_;  // no /proc: keep the count
    const double own = ownCpuSeconds();
    if (started_) {
        const double otherCores = ((busy - busy_) - (own - own_)) / (wall - wall_);
        const int wanted = threadsBeside(usable_, otherCores);
        if (wanted != threads_) omp_set_num_threads(threads_ = wanted);
    }
    started_ = true, wall_ = wall, busy_ = busy, own_ = own;
    return threads_;
}

}  // namespace rend
