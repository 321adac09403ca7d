#pragma once
// Shared by the cases of bench_accuracy (bench/bench_accuracy.cpp): CSV rows
// `case,setting,wall_seconds,error`, sweeps ("families") from coarse to fine, and a note where a
// family's error fails to fall.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

namespace rend::bench {

using Clock = std::chrono::steady_clock;

inline double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

inline std::string fmt(const char* format, double value) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, format, value);
    return buffer;
}

/// Runs `run` (returning a struct whose first member is its wall seconds) and, when it is short,
/// repeats it and keeps the fastest: other processes on the machine add noise, never speed.
template <class Run>
auto timed(Run run) {
    auto best = run();
    double spent = best.seconds;
    for (int k = 0; k < 4 && spent < 1.0; ++k) {
        auto again = run();
        spent += again.seconds;
        if (again.seconds < best.seconds) best = again;
    }
    return best;
}

inline std::string loadAverage() {
    std::ifstream in("/proc/loadavg");
    double one = 0.0;
    in >> one;
    return in ? fmt("%.2f", one) : std::string("unknown");
}

struct Point {
    std::string label;
    double seconds;
    double error;
};

/// A sweep from coarse to fine; `why` explains in advance what limits it, printed only if the
/// error fails to fall (the sweep's own diagnostics are appended by the case).
struct Family {
    std::string caseName;
    std::string name;
    std::vector<Point> points;
    std::string why;
};

/// Collects every row so the file gets the same text as stdout.
class Report {
public:
    void line(const std::string& text) {
        std::printf("%s\n", text.c_str());
        std::fflush(stdout);  // rows appear as they are measured: the run takes minutes
        text_ += text + "\n";
    }
    void row(const Family& f, const Point& p) {
        line(f.caseName + "," + f.name + "/" + p.label + "," + fmt("%.4g", p.seconds) + "," +
             fmt("%.4e", p.error));
    }
    /// Refinement must lower the error at every step; otherwise, or when the last step gains
    /// under 10% (the sweep has hit a floor), say where and why.
    void checkMonotone(const Family& f) {
        for (std::size_t k = 1; k < f.points.size(); ++k)
            if (!(f.points[k].error < f.points[k - 1].error)) {
                line("# note: " + f.caseName + " " + f.name + ": error does not fall from " +
                     f.points[k - 1].label + " (" + fmt("%.3e", f.points[k - 1].error) + ") to " +
                     f.points[k].label + " (" + fmt("%.3e", f.points[k].error) + "): " + f.why);
                return;
            }
        const std::size_t n = f.points.size();
        if (n >= 2 && f.points[n - 1].error > 0.9 * f.points[n - 2].error)
            line("# note: " + f.caseName + " " + f.name + ": falls but saturates at " +
                 fmt("%.3e", f.points[n - 1].error) + ": " + f.why);
    }
    const std::string& text() const { return text_; }

private:
    std::string text_;
};

/// The cases beyond bench_accuracy.cpp's own (patch, wave, diffusion) live one per file under
/// bench/accuracy/ and register themselves:  `const CaseRegistration kStrip{40, "strip", &run};`
/// main runs them after its own, in `order`, or only the one named by `--only NAME`.
struct CaseEntry {
    int order;
    const char* name;
    void (*run)(Report&);
};

inline std::vector<CaseEntry>& registeredCases() {
    static std::vector<CaseEntry> cases;
    return cases;
}

struct CaseRegistration {
    CaseRegistration(int order, const char* name, void (*run)(Report&)) {
        registeredCases().push_back({order, name, run});
    }
};

}  // namespace rend::bench
