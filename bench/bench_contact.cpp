// What contact costs (issue 13), printed as figures, never pass/fail:
//  1. off: the stretch scene with no ground, with the ground it draws, and with self-contact on
//     while nothing touches, ns per particle-step each, in the same run;
//  2. the share of the step contact takes in the three contact scenes at final quality (about
//     250K particles), over their first steps (the sheets start untouched: what ContactCulling
//     saves), 1 thread;
//  3. the share at a quarter of a million particles where everything touches: two pieces of a
//     sheet lying on each other on the ground, the upper one sliding, so every particle is in
//     contact and the candidate lists are rebuilt as it slides.
// Usage: bench_contact [steps] [off|scenes|pile] (default 200 for the large sheet: long enough
// for its skin to adapt; the scenes run a quarter of that); a part's name runs that part alone

#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "app/Scene.h"
#include "sim/Membrane.h"

namespace {

using rend::sim::Membrane;
using rend::sim::MembraneParams;

double nsPerParticleStep(const MembraneParams& p, int warmUp, int steps) {
    Membrane m(p);
    for (int s = 0; s < warmUp; ++s) m.step();
    const double t0 = omp_get_wtime();
    for (int s = 0; s < steps; ++s) m.step();
    return (omp_get_wtime() - t0) * 1e9 / (double(steps) * m.particleCount());
}

void costWhenOff() {
    const std::string file = std::string(REND_SOURCE_DIR) + "/scenes/stretch.toml";
    const MembraneParams none = rend::loadScene(file, {"contact.ground=false"}).sim;
    const MembraneParams ground = rend::loadScene(file).sim;
    const MembraneParams self = rend::loadScene(file, {"contact.self=true"}).sim;
    std::printf("stretch scene, 1 thread, ns per particle-step (3 rounds):\n");
    omp_set_num_threads(1);
    for (int round = 0; round < 3; ++round) {
        const double a = nsPerParticleStep(none, 200, 400);
        const double b = nsPerParticleStep(ground, 200, 400);
        const double c = nsPerParticleStep(self, 200, 400);
        std::printf(
            "  no contact %.1f | ground %.1f (%.3fx) | self-contact, untouched %.1f (%.3fx)\n", a,
            b, b / a, c, c / a);
    }
}

void scenesAtFinalQuality(int steps) {
    omp_set_num_threads(1);
    for (const char* name : {"foil_drape", "film_poke", "towel_pile"}) {
        const std::string file = std::string(REND_SOURCE_DIR) + "/scenes/" + name + ".toml";
        Membrane m(rend::loadScene(file, {"sheet.quality=final"}).sim);
        for (int s = 0; s < 5; ++s) m.step();
        const double before = m.contactSeconds(), t0 = omp_get_wtime();
        for (int s = 0; s < steps; ++s) m.step();
        const double total = omp_get_wtime() - t0, contact = m.contactSeconds() - before;
        std::printf(
            "%s final, %d particles, 1 thread: %.1f ms per step, contact %.1f ms (%.0f%% of the "
            "step), %d particles searched at the last list build\n",
            name, m.particleCount(), 1e3 * total / steps, 1e3 * contact / steps,
            100.0 * contact / total, m.contact()->lastSearched());
    }
}

/// Two pieces of a sheet cut across y = 0, the upper laid on the lower (within the contact
/// thickness) on the ground, sliding along x at 0.3 m/s.
Membrane slidingPieces(double dx) {
    MembraneParams p;
    p.sheet.size = {1.0, 2.0};
    p.sheet.dx = dx;
    p.sheet.center.z() = 0.25 * dx;
    p.material.youngsModulus = 1e6;
    p.material.density = 1000;
    p.gravity = {0.0, 0.0, -9.81};
    p.notches.push_back({{{-1.0, 0.3 * dx}, {1.0, 0.3 * dx}}});
    p.contact.ground = {true, 0.0, {0.5, 0.5}};
    p.contact.self.enabled = true;
    Membrane m(p);
    for (int i = 0; i < m.particleCount(); ++i) {
        if (m.restPositions()[i].y() < 0.3 * dx) continue;
        m.positions()[i] += Eigen::Vector3d(0.0, -1.0, 0.5 * dx);  // d above: touching
        m.velocities()[i] = Eigen::Vector3d(0.3, 0.0, 0.0);
    }
    return m;
}

void shareAtScale(int steps) {
    for (const int threads : {1, 2}) {
        omp_set_num_threads(threads);
        Membrane m = slidingPieces(0.00304);
        for (int s = 0; s < 5; ++s) m.step();
        const double before = m.contactSeconds();
        const long builds = m.contact()->listBuilds();
        const double t0 = omp_get_wtime();
        for (int s = 0; s < steps; ++s) m.step();
        const double total = omp_get_wtime() - t0, contact = m.contactSeconds() - before;
        std::printf(
            "%d particles, %d thread(s): %.1f ms per step, contact %.1f ms (%.0f%% of the "
            "step), %zu contacts, %ld list builds in %d steps\n",
            m.particleCount(), threads, 1e3 * total / steps, 1e3 * contact / steps,
            100.0 * contact / total, m.contact()->lastPairCount(),
            m.contact()->listBuilds() - builds, steps);
    }
}

}  // namespace

int main(int argc, char** argv) {
    const int steps = argc > 1 ? std::atoi(argv[1]) : 200;
    const std::string only = argc > 2 ? argv[2] : "";
    if (only != "" && only != "off" && only != "scenes" && only != "pile") {
        std::fprintf(stderr, "bench_contact: expected off, scenes or pile, found \"%s\"\n",
                     only.c_str());
        return 2;
    }
    if (only == "" || only == "off") costWhenOff();
    if (only == "" || only == "scenes") scenesAtFinalQuality(std::max(1, steps / 4));
    if (only == "" || only == "pile") shareAtScale(steps);
    return 0;
}
