// The steps that scripts/bench_instructions.sh counts under callgrind: a scene's membrane, square
// lattice (or another), dt 1e-4, one bond law (as bench_speed's per-law rows), stepped `warm` times
// and then `steps` times inside measuredSteps(), the one function the script has callgrind count
// (--toggle-collect), so that neither the set-up nor the first steps' allocations are counted.
// Prints the particles and steps, which the script divides the counts by.
//
//   build/bench_instructions SCENE LAW [WARM STEPS [LATTICE [DT]]]   (scenes/SCENE; 5 and 20
//   steps, the square lattice and dt 1e-4 by default; LATTICE square, hexagonal, or scene: the
//   scene's own; DT seconds, or scene: the scene's own, "adaptive" unless it says otherwise,
//   stepped frame by frame as a run does, WARM and STEPS then counting frames)

#include <omp.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "app/Scene.h"
#include "sim/Membrane.h"

namespace {

/// The counted steps: callgrind collects from this function's entry to its return.
[[gnu::noinline]] void measuredSteps(rend::sim::Membrane& membrane, int steps) {
    for (int k = 0; k < steps; ++k) membrane.step();
    asm volatile("" ::: "memory");  // not folded into the caller's loop
}

/// The counted frames [first, last) of a scene run as shipped (Membrane::advanceTo: adaptive
/// steps, chosen frame by frame), their steps counted as measuredSteps' (the same pattern).
[[gnu::noinline]] void measuredStepsOfFrames(rend::sim::Membrane& membrane, double frame, int first,
                                             int last) {
    for (int f = first; f < last; ++f) membrane.advanceTo((f + 1) * frame);
    asm volatile("" ::: "memory");
}

/// `text` as a whole number in [low, high], or a message and false.
bool countOf(const char* what, const char* text, int low, int high, int& out) {
    char* end = nullptr;
    const long value = std::strtol(text, &end, 10);
    if (end == text || *end != '\0' || value < low || value > high) {
        std::fprintf(stderr, "bench_instructions: %s '%s': expected a whole number from %d to %d\n",
                     what, text, low, high);
        return false;
    }
    out = int(value);
    return true;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 3 && argc != 5 && argc != 6 && argc != 7) {
        std::fprintf(stderr,
                     "bench_instructions: expected SCENE LAW [WARM STEPS [LATTICE [DT]]] (e.g. "
                     "stretch.toml linear 5 20 square 1e-4)\n");
        return 2;
    }
    const std::string lattice = argc >= 6 ? argv[5] : "square";
    if (lattice != "square" && lattice != "hexagonal" && lattice != "scene") {
        std::fprintf(stderr,
                     "bench_instructions: LATTICE '%s': expected square, hexagonal or scene\n",
                     argv[5]);
        return 2;
    }
    int warm = 5, steps = 20;
    if (argc >= 5 && (!countOf("WARM", argv[3], 1, 100000, warm) ||
                      !countOf("STEPS", argv[4], 1, 100000, steps)))
        return 2;
    const std::string law = argv[2];
    if (law != "linear" && law != "power_law" && law != "elastoplastic") {
        std::fprintf(stderr,
                     "bench_instructions: LAW '%s': expected linear, power_law or elastoplastic\n",
                     argv[2]);
        return 2;
    }
    const std::string dt = argc == 7 ? argv[6] : "1e-4";
    char* end = nullptr;
    const double seconds = std::strtod(dt.c_str(), &end);
    if (dt != "scene" && (end == dt.c_str() || *end != '\0' || !(seconds > 0.0))) {
        std::fprintf(stderr, "bench_instructions: DT '%s': expected seconds above 0, or scene\n",
                     dt.c_str());
        return 2;
    }
    std::vector<std::string> sets = {"material.law=\"" + law + "\""};
    if (dt != "scene") sets.push_back("time.dt=" + dt);
    if (lattice != "scene") sets.push_back("sheet.lattice=\"" + lattice + "\"");
    try {
        const rend::Scene s =
            rend::loadScene(std::string(REND_SOURCE_DIR) + "/scenes/" + argv[1], sets);
        omp_set_num_threads(1);
        rend::sim::Membrane membrane(s.sim);
        if (dt == "scene") {  // WARM and STEPS are frames
            const double frame = 1.0 / s.sim.time.fps;
            for (int f = 0; f < warm; ++f) membrane.advanceTo((f + 1) * frame);
            const long before = membrane.stepCount();
            measuredStepsOfFrames(membrane, frame, warm, warm + steps);
            steps = int(membrane.stepCount() - before);
        } else {
            for (int k = 0; k < warm; ++k) membrane.step();
            measuredSteps(membrane, steps);
        }
        std::printf("particles %d steps %d\n", membrane.particleCount(), steps);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_instructions: %s\n", e.what());
        return 1;
    }
    return 0;
}
