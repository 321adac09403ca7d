#include "app/Threads.h"

#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
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
