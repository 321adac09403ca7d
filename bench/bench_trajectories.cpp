// The membrane paper's Fig. 9 for every solver: the XY trajectories of the particles at
// P1 (0.64, 0.84) and P2 (1.64, 1.64) of the 2 x 2 sheet (paper coordinates from its corner; the
// scene is centred, so they are (-0.36, -0.16) and (0.64, 0.64) here) in the large-stretching
// scene, sampled every frame, and each solver's seconds per step on its 11.7K particles.
//
//   bench_trajectories [out.csv] [--duration SECONDS]     (then scripts/plot_trajectories.py)

#include <omp.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "app/Pipeline.h"
#include "app/Scene.h"

namespace {

constexpr const char* kSolvers[] = {"peridynamic", "fem_cst", "mass_spring_vg", "mass_spring_tp",
                                    "sph"};

}  // namespace

int main(int argc, char** argv) {
    std::string csvPath;
    double duration = 0.0;  // 0: the scene's
    for (int k = 1; k < argc; ++k) {
        if (std::string(argv[k]) == "--duration" && k + 1 < argc)
            duration = std::stod(argv[++k]);
        else
            csvPath = argv[k];
    }
    std::string csv = "solver,t,p1_x,p1_y,p2_x,p2_y\n";
    std::printf("# %d threads; seconds per step on the stretch scene\n", omp_get_max_threads());
    for (const char* solver : kSolvers) {
        std::vector<std::string> set = {std::string("solver=") + solver};
        if (duration > 0) set.push_back("time.duration=" + std::to_string(duration));
        const rend::Scene scene = rend::loadScene(REND_SOURCE_DIR "/scenes/stretch.toml", set);
        rend::sim::Membrane m = rend::prepareMembrane(scene);
        const auto [substeps, dt] = rend::substepsPerFrame(m.timeStep(), scene.sim.time.fps);
        m.setTimeStep(dt);
        const int p1 = m.nearestParticle({-0.36, -0.16}), p2 = m.nearestParticle({0.64, 0.64});
        const auto start = std::chrono::steady_clock::now();
        for (int frame = 0; frame <= scene.frameCount(); ++frame) {
            if (frame > 0)
                for (int s = 0; s < substeps; ++s) m.step();
            const auto& x = m.positions();
            char row[256];  // paper coordinates: shifted by (1, 1)
            std::snprintf(row, sizeof row, "%s,%.6g,%.9g,%.9g,%.9g,%.9g\n", solver, m.time(),
                          x[p1].x() + 1, x[p1].y() + 1, x[p2].x() + 1, x[p2].y() + 1);
            csv += row;
        }
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::printf(
            "%-15s %d particles, %ld steps: %.3g ms per step; P1 ends at (%.4f, %.4f), "
            "P2 at (%.4f, %.4f)\n",
            solver, m.particleCount(), m.stepCount(), 1e3 * seconds / m.stepCount(),
            m.positions()[p1].x() + 1, m.positions()[p1].y() + 1, m.positions()[p2].x() + 1,
            m.positions()[p2].y() + 1);
        std::fflush(stdout);
    }
    if (!csvPath.empty()) {
        std::ofstream out(csvPath);
        out << csv;
        if (!out) {
            std::fprintf(stderr, "error: cannot write %s\n", csvPath.c_str());
            return 1;
        }
    }
    return 0;
}
