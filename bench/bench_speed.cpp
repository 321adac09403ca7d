// Issue 16's speed figures in one run: the membrane step of scenes/stretch.toml on a square
// lattice at dt = 1e-4 (the sheet LAMMPS's peri/pmb is compared on), grown from 10^4 to 10^7
// particles at the same spacing. Per size: the bonds per particle, the bytes per particle (the
// heap the membrane and its first steps hold), and ns per particle-step on 1 thread
// and on every usable core, with the speed-up. When `lmp` is on the PATH, LAMMPS runs the
// 10,201-particle sheet with peri/pmb just before and just after each one-thread figure it is
// compared with, on the same core, and the faster run's ratio to rend is printed. Then,
// per bond law (linear, power_law, elastoplastic), ns per particle-step on 1 thread of the same
// sheet, and of crack_path_sources (its notch breaking, two heat sources diffusing: theta and
// breaking on), both square at dt 1e-4, and crack_path_sources on its own hexagonal lattice (every
// shipped scene's: 6 bonds a particle, not 8); with --largest 1e6 or more, crack_path_sources too
// on a sheet 20 m square at its spacing (1,002,001 particles, 20 steps in), and with 1e7 on one
// 63.24 m square (10,004,569 particles, 5 steps in). The linear and
// elastoplastic laws again with the kick and drift in their own pass after the forces
// (Membrane::setKickInPass(false), the order until 2026-11-27): what the change saves. And the
// diffusion alone (eq. 25, Diffusion::advance) of the linear law's crack_path_sources sheets,
// after their steps: ns per particle-step on 1 thread. Last, crack_path_sources as shipped
// (hexagonal, adaptive steps, frame by frame) for the linear and elastoplastic laws, with the
// adaptive step's failure approach rate measured in the next step's force pass and in a pass of
// its own (Membrane::setApproachInPass(false)): what that saves. Then crack_path_sources (square,
// linear) with its bonds reaching 1.5, 2.2 and 3 dx (8, 12 and 28 bonds a particle): ns per
// particle-step and per bond, and its diffusion alone. Then seconds a frame of
// foil_tear_heat at final quality with a cache file a frame, written by the run itself and by a
// thread of its own while the next frame simulates (app/CacheWriter.h).
//
// Every rend figure is the fastest of five spans of its steps, and the one-thread rows and
// LAMMPS run pinned to one core, the fastest of the usable ones by a dependent add loop at the
// start (or --cpu K). On this VM a core loses up to a third of its speed for minutes at a time
// to another guest: on 2026-11-28 one core ran 2.5 dependent adds per ns and the other 3.5,
// then both 3.5 half an hour later (LAMMPS 105 ns on the one, 157 on the other), so a median or
// a mean of runs minutes apart, or on either core, measures that guest.
//
//   build/bench_speed [--largest N] [--cpu K]   (sizes 1e4, 1e5, 1e6, 1e7 up to N, default 1e7)
//   REND_SIMD=avx2 build/bench_speed  (the four-lane kernels on a CPU with AVX-512)

#include <malloc.h>
#include <omp.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "app/Cache.h"
#include "app/CacheWriter.h"
#include "app/Pipeline.h"
#include "app/Scene.h"
#include "app/Threads.h"
#include "sim/Diffusion.h"
#include "sim/Membrane.h"
#include "sim/StepKernels.h"

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Bytes the heap holds (glibc's mallinfo2: in the arenas and in mapped blocks). Unlike the
/// resident size it counts memory reused after an earlier sheet was freed.
double heapBytes() {
    const struct mallinfo2 m = mallinfo2();
    return double(m.uordblks) + double(m.hblkhd);
}

/// The calling thread on one CPU while it lives (children started meanwhile inherit it), its
/// own mask back after; nothing where `cpu` is negative or the kernel refuses.
class PinnedThread {
public:
    explicit PinnedThread(int cpu) {
        if (cpu < 0 || sched_getaffinity(0, sizeof saved_, &saved_) != 0) return;
        cpu_set_t one;
        CPU_ZERO(&one);
        CPU_SET(cpu, &one);
        pinned_ = sched_setaffinity(0, sizeof one, &one) == 0;
    }
    ~PinnedThread() {
        if (pinned_) sched_setaffinity(0, sizeof saved_, &saved_);
    }
    PinnedThread(const PinnedThread&) = delete;
    PinnedThread& operator=(const PinnedThread&) = delete;

private:
    cpu_set_t saved_{};
    bool pinned_ = false;
};

/// The core the one-thread rows and LAMMPS run on (-1: wherever the scheduler puts them).
int gOneCore = -1;

/// Dependent integer adds per ns on `cpu`: the best of five loops of 2e7 (a few ms each).
double addsPerNs(int cpu) {
    const PinnedThread pin(cpu);
    constexpr long kAdds = 20000000;
    double best = 0.0;
    for (int round = 0; round < 5; ++round) {
        unsigned long x = 0;
        const auto start = Clock::now();
        for (long k = 0; k < kAdds; ++k) {
            asm volatile("" : "+r"(x));  // one dependent add per iteration, kept in a register
            ++x;
        }
        best = std::max(best, kAdds / std::max(secondsSince(start), 1e-9) * 1e-9);
    }
    return best;
}

/// The fastest CPU of the affinity mask by addsPerNs, each one's speed printed.
int fastestCpu() {
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) != 0) return -1;
    int best = -1;
    double bestSpeed = 0.0;
    std::printf("core speeds (dependent adds per ns):");
    for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
        if (!CPU_ISSET(cpu, &set)) continue;
        const double speed = addsPerNs(cpu);
        std::printf(" cpu %d %.2f", cpu, speed);
        if (speed > bestSpeed) best = cpu, bestSpeed = speed;
    }
    return best;
}

/// ns per particle of `step` (one step of `particles`), over enough steps to take about
/// `seconds`: the fastest of kSpans spans of at least 2 steps each (time another process takes
/// from a core only adds).
template <class Step>
double fastestSpan(Step&& step, int particles, double seconds) {
    constexpr int kSpans = 5;
    step();  // the first step at this thread count pays for the thread pool
    auto start = Clock::now();
    step();
    const double one = std::max(secondsSince(start), 1e-6);
    const int steps = std::max(2, int(seconds / kSpans / one));
    double best = std::numeric_limits<double>::infinity();
    for (int span = 0; span < kSpans; ++span) {
        start = Clock::now();
        for (int s = 0; s < steps; ++s) step();
        best = std::min(best, secondsSince(start) / steps / particles * 1e9);
    }
    return best;
}

/// ns per particle-step of the membrane (fastestSpan); on one thread, on gOneCore.
double nsPerParticleStep(rend::sim::Membrane& membrane, int threads, double seconds) {
    const PinnedThread pin(threads == 1 ? gOneCore : -1);
    omp_set_num_threads(threads);
    return fastestSpan([&] { membrane.step(); }, membrane.particleCount(), seconds);
}

/// ns per particle-step of the diffusion alone (eq. 25: Diffusion::advance, with the sub-steps
/// the step needs), on one thread on gOneCore: a diffusion built as the membrane builds its
/// own, advancing a copy of the membrane's theta over its bonds' life.
double diffusionNsPerParticleStep(const rend::sim::Membrane& membrane, double seconds) {
    rend::sim::Diffusion diffusion(membrane.params(), membrane.restPositions(), membrane.bonds(),
                                   membrane.volumes());
    std::vector<double> theta = membrane.theta();
    const rend::sim::DamageState& damage = membrane.damageState();
    double t = membrane.time();
    const double dt = membrane.timeStep();
    const PinnedThread pin(gOneCore);
    omp_set_num_threads(1);
    return fastestSpan(
        [&] {
            diffusion.advance(theta, damage, t, dt);
            t += dt;
        },
        membrane.particleCount(), seconds);
}

struct Row {
    long particles = 0;
    double bondsPerParticle = 0.0, bytesPerParticle = 0.0, setupSeconds = 0.0;
    double ns1 = 0.0, nsAll = 0.0;
};

/// The stretch scene at `side` x `side` particles, loaded at that size so that its grips (the
/// edges' strips) are placed on the sheet's edges, as `rend run --set sheet.size=...` does.
rend::sim::MembraneParams stretchSheet(int side) {
    const std::string size = std::to_string((side - 1) * 0.02);
    return rend::loadScene(std::string(REND_SOURCE_DIR) + "/scenes/stretch.toml",
                           {"sheet.lattice=\"square\"", "time.dt=1e-4", "sheet.dx=0.02",
                            "sheet.size=[" + size + ", " + size + "]"})
        .sim;
}

Row measure(const rend::sim::MembraneParams& params, int cores) {
    Row row;
    const double before = heapBytes();
    const auto start = Clock::now();
    rend::sim::Membrane membrane(params);
    row.setupSeconds = secondsSince(start);
    row.particles = membrane.particleCount();
    row.bondsPerParticle = double(membrane.bonds().directedCount()) / row.particles;
    // One thread first: steps on every core before it left the one-thread figure 10-20% slower
    // at 10^5 particles (and taskset -c 0 agreed with the one-thread-first figure).
    omp_set_num_threads(1);
    membrane.step();  // the solvers' workspaces are allocated at the first step
    row.bytesPerParticle = (heapBytes() - before) / row.particles;
    row.ns1 = nsPerParticleStep(membrane, 1, 2.0);
    row.nsAll = cores > 1 ? nsPerParticleStep(membrane, cores, 2.0) : row.ns1;
    return row;
}

/// peri/pmb on rend's 10,201-particle square sheet (101 x 101, 0.02 m, horizon 1.5 dx: 7.9
/// bonds each, as rend's), 500 steps of 1e-4 s on one thread. Returns ns per particle-step, or
/// a negative number when `lmp` is missing or its output does not parse.
double lammpsNsPerParticleStep() {
    if (std::system("command -v lmp > /dev/null 2>&1") != 0) return -1.0;
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("rend_bench_speed_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "in.peri") << R"(units si
dimension 3
boundary f f f
atom_style peri
atom_modify map array
lattice sc 0.02
region box block -3 103 -3 103 -3 3
region sheet block -0.5 100.5 -0.5 100.5 -0.5 0.5
create_box 1 box
create_atoms 1 region sheet
pair_style peri/pmb
pair_coeff * * 1.0e12 0.0301 0.005 0.25
set group all density 2000.0
set group all volume 8.0e-6
velocity all create 1.0e-6 87287 loop geom
fix 1 all nve
neighbor 0.005 bin
neigh_modify every 1000 delay 0 check yes
timestep 1.0e-4
thermo 1000
run 500
)";
    const std::string command =
        "cd '" + dir.string() + "' && OMP_NUM_THREADS=1 lmp -in in.peri -log none > out.txt 2>&1";
    const PinnedThread pin(gOneCore);  // the same core as rend's one-thread rows
    const int status = std::system(command.c_str());
    std::ifstream in(dir / "out.txt");
    std::stringstream text;
    text << in.rdbuf();
    std::filesystem::remove_all(dir);
    if (status != 0) return -1.0;
    std::smatch m;
    const std::string out = text.str();
    const std::regex loop(
        R"(Loop time of ([0-9.eE+-]+) on \d+ procs for (\d+) steps with (\d+) atoms)");
    if (!std::regex_search(out, m, loop)) return -1.0;
    return std::stod(m[1]) / std::stod(m[2]) / std::stod(m[3]) * 1e9;
}

constexpr const char* kLaws[] = {"linear", "power_law", "elastoplastic"};

/// ns per particle-step on 1 thread of `scene` with [material] law = `law`, after `warm` steps;
/// with `side` > 0, on a sheet `side` metres square at the scene's spacing.
/// With `diffusion`, the diffusion alone of the same membrane after the steps
/// (diffusionNsPerParticleStep) too. On the square lattice, or with `hexagonal` the scene's own
/// (every shipped scene's: 6 bonds a particle where the square one has 8).
double lawRow(const std::string& scene, const char* law, double side = 0.0, int warm = 200,
              bool kickInPass = true, double* diffusion = nullptr, bool hexagonal = false) {
    std::vector<std::string> sets = {
        hexagonal ? "sheet.lattice=\"hexagonal\"" : "sheet.lattice=\"square\"", "time.dt=1e-4",
        std::string("material.law=\"") + law + "\""};
    if (side > 0.0) {
        const std::string size = std::to_string(side);
        sets.push_back("sheet.size=[" + size + ", " + size + "]");
        sets.push_back("time.allow_slow=true");  // its whole duration would be hours
    }
    const rend::Scene s = rend::loadScene(std::string(REND_SOURCE_DIR) + "/scenes/" + scene, sets);
    rend::sim::Membrane membrane(s.sim);
    membrane.setKickInPass(kickInPass);
    omp_set_num_threads(1);
    for (int k = 0; k < warm; ++k) membrane.step();
    const double ns = nsPerParticleStep(membrane, 1, 2.0);
    if (diffusion) *diffusion = diffusionNsPerParticleStep(membrane, 1.0);
    return ns;
}

/// ns per particle-step (and per directed bond) on 1 thread of crack_path_sources, square, dt
/// 1e-4, linear law, with the bonds reaching `horizon` dx: its bonds per particle, ns per
/// particle-step, and the diffusion alone after the steps.
std::array<double, 3> horizonRow(double horizon) {
    const rend::Scene s =
        rend::loadScene(std::string(REND_SOURCE_DIR) + "/scenes/crack_path_sources.toml",
                        {"sheet.lattice=\"square\"", "time.dt=1e-4", "material.law=\"linear\"",
                         "sheet.horizon=" + std::to_string(horizon)});
    rend::sim::Membrane membrane(s.sim);
    omp_set_num_threads(1);
    for (int k = 0; k < 100; ++k) membrane.step();
    const double ns = nsPerParticleStep(membrane, 1, 2.0);
    return {double(membrane.bonds().directedCount()) / membrane.particleCount(), ns,
            diffusionNsPerParticleStep(membrane, 1.0)};
}

/// ns per particle-step on 1 thread of crack_path_sources as shipped (its hexagonal lattice,
/// time.dt = "adaptive") with [material] law = `law`, stepped frame by frame (Membrane::advanceTo)
/// with the failure approach rate measured in the next step's force pass, and in a pass of its
/// own after every step (Membrane::setApproachInPass(false), the order until 2026-11-29): two
/// membranes advanced through the same frames, in alternate spans of 12 frames after 24, the
/// fastest span of five each. The same steps and bits: what the change saves.
std::array<double, 2> adaptiveRow(const char* law) {
    const rend::Scene s =
        rend::loadScene(std::string(REND_SOURCE_DIR) + "/scenes/crack_path_sources.toml",
                        {std::string("material.law=\"") + law + "\""});
    rend::sim::Membrane inPass(s.sim), ownPass(s.sim);
    ownPass.setApproachInPass(false);
    const PinnedThread pin(gOneCore);
    omp_set_num_threads(1);
    const double frame = 1.0 / s.sim.time.fps;
    int frames = 0;
    const auto advance = [&](rend::sim::Membrane& m, int count) {
        for (int f = 1; f <= count; ++f) m.advanceTo((frames + f) * frame);
    };
    advance(inPass, 24), advance(ownPass, 24), frames = 24;
    std::array<double, 2> fastest{std::numeric_limits<double>::infinity(),
                                  std::numeric_limits<double>::infinity()};
    for (int span = 0; span < 5; ++span, frames += 12) {
        int k = 0;
        for (rend::sim::Membrane* m : {&inPass, &ownPass}) {
            const long before = m->stepCount();
            const Clock::time_point start = Clock::now();
            advance(*m, 12);
            const double steps = double(m->stepCount() - before);
            fastest[k] =
                std::min(fastest[k], secondsSince(start) * 1e9 / steps / m->particleCount());
            ++k;
        }
    }
    return fastest;
}

/// Seconds per frame of foil_tear_heat at final quality (251,444 particles, elastoplastic,
/// adaptive steps) simulated on one thread with a cache file a frame (--cache-every 1): written
/// by the run itself after each frame (writeCacheFrame, the order until 2026-11-29), and by a
/// thread of its own while the next frame simulates (CacheWriter, waited for after it, as
/// rend run does). Two membranes through the same frames, in alternate spans of 4 frames after
/// 2, the fastest span of three each. Not pinned: the writer takes another core.
std::array<double, 2> cacheRow() {
    const rend::Scene s = rend::loadScene(
        std::string(REND_SOURCE_DIR) + "/scenes/foil_tear_heat.toml", {"sheet.quality=final"});
    rend::sim::Membrane inRun = rend::prepareMembrane(s), ownThread = rend::prepareMembrane(s);
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("rend_bench_cache_" + std::to_string(getpid()));
    omp_set_num_threads(1);
    rend::CacheWriter writer(dir / "own");
    const double frame = 1.0 / s.sim.time.fps;
    const auto cached = [&](rend::sim::Membrane& m, int f, std::vector<std::byte> reuse) {
        return rend::CacheFrame{f, m.time(), s.simulationFingerprint,
                                std::uint64_t(m.particleCount()), m.saveState(std::move(reuse))};
    };
    std::vector<std::byte> kept;
    const auto writtenInRun = [&](int first, int count) {
        for (int f = first; f < first + count; ++f) {
            inRun.advanceTo(f * frame);
            rend::CacheFrame c = cached(inRun, f, std::move(kept));
            rend::writeCacheFrame(dir / "run", c);
            kept = std::move(c.state);
        }
    };
    const auto writtenOnItsThread = [&](int first, int count) {
        for (int f = first; f < first + count; ++f) {
            ownThread.advanceTo(f * frame);
            writer.wait();
            writer.start(cached(ownThread, f, writer.takeStorage()));
        }
        writer.wait();  // the span ends with its frames written
    };
    writtenInRun(1, 2), writtenOnItsThread(1, 2);
    std::array<double, 2> fastest{std::numeric_limits<double>::infinity(),
                                  std::numeric_limits<double>::infinity()};
    for (int span = 0, first = 3; span < 3; ++span, first += 4) {
        Clock::time_point start = Clock::now();
        writtenInRun(first, 4);
        fastest[0] = std::min(fastest[0], secondsSince(start) / 4.0);
        start = Clock::now();
        writtenOnItsThread(first, 4);
        fastest[1] = std::min(fastest[1], secondsSince(start) / 4.0);
    }
    std::filesystem::remove_all(dir);
    return fastest;
}

/// A figure of rend's with LAMMPS's runs just before and after it on the same core (gOneCore),
/// the faster of the two: this VM's cores slow down for minutes at a time, so a ratio means
/// something only between runs seconds apart. lammps is negative without them.
struct Paired {
    double ns = 0.0, lammps = -1.0;
    double ratio() const { return lammps > 0.0 ? lammps / ns : -1.0; }
};

template <class Figure>
Paired paired(bool withLammps, Figure&& figure) {
    const double before = withLammps ? lammpsNsPerParticleStep() : -1.0;
    Paired p{figure(), -1.0};
    const double after = withLammps ? lammpsNsPerParticleStep() : -1.0;
    for (const double ns : {before, after})
        if (ns > 0.0 && (p.lammps < 0.0 || ns < p.lammps)) p.lammps = ns;
    return p;
}

}  // namespace

/// argv's whole number after `option` (all of it read, in [least, most]), or a message on
/// stderr and false: "1e6" is a million, where atol read 1 and ran 10^4 alone.
bool numberAfter(const char* option, const char* text, double least, double most, double& value) {
    char* end = nullptr;
    value = std::strtod(text, &end);
    if (end != text && *end == '\0' && value >= least && value <= most &&
        value == std::floor(value))
        return true;
    std::fprintf(stderr, "bench_speed: %s %s: expected a whole number from %g to %g\n", option,
                 text, least, most);
    return false;
}

int main(int argc, char** argv) {
    long largest = 10000000;
    int cpu = -1;
    bool cpuGiven = false;
    for (int k = 1; k < argc; k += 2) {
        const std::string option = argv[k];
        double value = 0.0;
        if ((option != "--largest" && option != "--cpu") || k + 1 >= argc) {
            std::fprintf(stderr, "bench_speed: %s: expected --largest N or --cpu K%s\n", argv[k],
                         k + 1 >= argc ? ", with its number" : "");
            return 2;
        }
        if (!numberAfter(argv[k], argv[k + 1], option == "--cpu" ? 0.0 : 1.0,
                         option == "--cpu" ? CPU_SETSIZE - 1 : 1e9, value))
            return 2;
        if (option == "--largest") largest = long(value);
        if (option == "--cpu") cpu = int(value), cpuGiven = true;
    }
    const int cores = rend::usableCores();
    const int width = rend::sim::simdWidth();
    std::printf(
        "scenes/stretch.toml, square lattice, dt 1e-4, peridynamic bonds; %d usable cores; "
        "kernels %d lanes wide (%s)\n",
        cores, width,
        width == 8   ? "AVX-512"
        : width == 4 ? "AVX2"
                     : "scalar");
    gOneCore = fastestCpu();
    if (cpuGiven) {
        cpu_set_t set;
        if (cpu < 0 || cpu >= CPU_SETSIZE || sched_getaffinity(0, sizeof set, &set) != 0 ||
            !CPU_ISSET(cpu, &set)) {
            std::fflush(stdout);
            std::fprintf(stderr,
                         "\nbench_speed: --cpu %d is not one of the CPUs this process may use "
                         "(the core speeds above list them)\n",
                         cpu);
            return 2;
        }
        gOneCore = cpu;
    }
    std::printf("; the 1-thread rows and LAMMPS on cpu %d\n", gOneCore);
    std::printf("%12s %10s %12s %10s %14s %14s %8s\n", "particles", "bonds/p", "bytes/p", "setup s",
                "ns/p-step 1t", "ns/p-step all", "speedup");
    // The per-law rows first, while the machine is quiet: freeing the 10^7 sheet's 9 GB keeps
    // the kernel busy for a while after it.
    const bool lmp = std::system("command -v lmp > /dev/null 2>&1") == 0;
    std::vector<std::array<Paired, 5>> laws;
    // crack_path_sources at 10^6 and at 10^7 particles too, where --largest reaches them (the
    // kick in its own pass not at 10^7: a minute's set-up for each row).
    const bool large = largest >= 1000000, huge = largest >= 10000000;
    std::array<double, 5> diffusion{};  // the diffusion alone, of the linear law's membranes
    const auto row = [&](const char* law, bool kickInPass) {
        const bool linear = std::string(law) == "linear" && kickInPass;
        int cell = 0;
        const auto crack = [&](double side, int warm, bool hexagonal = false) {
            double* alone = linear ? &diffusion[++cell] : nullptr;
            return paired(lmp, [&] {
                return lawRow("crack_path_sources.toml", law, side, warm, kickInPass, alone,
                              hexagonal);
            });
        };
        // Evaluated in this order (a braced list's), as the diffusion's cells are numbered.
        return std::array<Paired, 5>{
            paired(lmp, [&] { return lawRow("stretch.toml", law, 0.0, 200, kickInPass); }),
            crack(0.0, 200), crack(0.0, 200, true), large ? crack(20.0, 20) : Paired{},
            huge && kickInPass ? crack(63.24, 5) : Paired{}};
    };
    for (const char* law : kLaws) laws.push_back(row(law, true));
    for (const int k : {0, 2}) laws.push_back(row(kLaws[k], false));  // the kick in its own pass
    Paired at1e4;
    for (const int side : {101, 317, 1001, 3163}) {
        if (side > 101 && long(side) * side > largest * 1.01) break;  // 10^4 always runs
        Row r;
        const Paired p = paired(lmp && side == 101, [&] {
            r = measure(stretchSheet(side), cores);
            return r.ns1;
        });
        if (side == 101) at1e4 = p;
        std::printf("%12ld %10.2f %12.0f %10.2f %14.1f %14.1f %8.2f\n", r.particles,
                    r.bondsPerParticle, r.bytesPerParticle, r.setupSeconds, r.ns1, r.nsAll,
                    r.ns1 / r.nsAll);
        std::fflush(stdout);
    }
    if (at1e4.lammps < 0.0) {
        std::printf("LAMMPS: lmp not found or its run failed: no ratio (apt-get install lammps)\n");
    } else {
        std::printf(
            "LAMMPS peri/pmb, 10,201 particles, 1 thread, on the same core just before and after "
            "rend's row: %.1f ns per particle-step (the faster run); rend %.1f: rend is %.2fx "
            "faster\n",
            at1e4.lammps, at1e4.ns, at1e4.lammps / at1e4.ns);
    }
    std::printf(
        "\nns per particle-step, 1 thread, square lattice (one column the scene's own hexagonal "
        "one), dt 1e-4, per bond law\n");
    const int columns = 3 + int(large) + int(huge);
    const char* headers[] = {"stretch (10,201)", "crack_path_sources (theta, breaking)",
                             "the same, hexagonal (11,658)", "the same at 1,002,001",
                             "the same at 10,004,569"};
    const int widths[] = {18, 36, 28, 26, 26};
    const char* names[] = {kLaws[0], kLaws[1], kLaws[2], "linear, kick in own pass",
                           "elastoplastic, kick in own pass"};
    const auto table = [&](auto&& cell) {
        for (std::size_t k = 0; k < laws.size(); ++k) {
            std::printf("%-32s", names[k]);
            for (int c = 0; c < columns; ++c) cell(laws[k][c], widths[c]);
            std::printf("\n");
        }
    };
    std::printf("%-32s", "law");
    for (int c = 0; c < columns; ++c) std::printf(" %*s", widths[c], headers[c]);
    std::printf("\n");
    table([](const Paired& p, int width) {
        if (p.ns > 0.0)
            std::printf(" %*.1f", width, p.ns);
        else
            std::printf(" %*s", width, "-");
    });
    std::printf("%-32s %*s", "diffusion alone (linear's)", widths[0], "-");
    for (int c = 1; c < columns; ++c) std::printf(" %*.1f", widths[c], diffusion[c]);
    std::printf("\n");
    std::printf(
        "\nns per particle-step, 1 thread, crack_path_sources as shipped (hexagonal, 11,658 "
        "particles, adaptive steps, frame by frame), its failure approach rate measured\n%-32s "
        "%18s %18s %10s\n",
        "law", "in the force pass", "in its own pass", "saved");
    for (const char* law : {kLaws[0], kLaws[2]}) {
        const std::array<double, 2> ns = adaptiveRow(law);
        std::printf("%-32s %18.1f %18.1f %9.0f%%\n", law, ns[0], ns[1],
                    100.0 * (1.0 - ns[0] / ns[1]));
    }
    std::printf(
        "\nns per particle-step, 1 thread, crack_path_sources (square, 10,201 particles, dt 1e-4, "
        "linear, theta and breaking) by horizon\n%-10s %10s %14s %12s %16s\n",
        "horizon", "bonds/p", "ns/p-step", "ns/bond", "diffusion alone");
    for (const double horizon : {1.5, 2.2, 3.0}) {
        const std::array<double, 3> h = horizonRow(horizon);
        std::printf("%-10.1f %10.2f %14.1f %12.2f %16.1f\n", horizon, h[0], h[1], h[1] / h[0],
                    h[2]);
        std::fflush(stdout);
    }
    const std::array<double, 2> frameSeconds = cacheRow();
    std::printf(
        "\nseconds a frame, foil_tear_heat at final quality (251,444 particles, elastoplastic, "
        "adaptive), 1 thread, a cache file a frame\n%-32s %18s %18s %10s\n%-32s %18.3f %18.3f "
        "%9.0f%%\n",
        "", "written in the run", "on its own thread", "saved", "frame and cache", frameSeconds[0],
        frameSeconds[1], 100.0 * (1.0 - frameSeconds[1] / frameSeconds[0]));
    if (!lmp) return 0;
    std::printf(
        "\nthe same as times faster than LAMMPS peri/pmb (10,201 particles) run on the same core "
        "just before and after each figure (issue 16: 10x)\n");
    double slowest = 0.0, fastest = std::numeric_limits<double>::infinity();
    table([&](const Paired& p, int width) {
        if (p.lammps > 0.0) {
            slowest = std::max(slowest, p.lammps), fastest = std::min(fastest, p.lammps);
            std::printf(" %*.1fx", width - 1, p.ratio());
        } else {
            std::printf(" %*s", width, "-");
        }
    });
    std::printf("(LAMMPS's figure beside them: %.1f to %.1f ns per particle-step)\n", fastest,
                slowest);
}
