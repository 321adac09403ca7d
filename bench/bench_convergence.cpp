// Does a tear converge under refinement? The tearing scenes run at dx and dx/2 with the same
// R/dx (the scenes' horizon = 1.5) and the same time step, and at the same simulated times the
// table compares the crack's length (the extent of the broken bonds' rest midpoints along the
// crack direction, the pre-cut notch included) and the broken-bond fraction. A converged tear
// has the same length at both dx; the fraction is not resolution-free (a crack of given length
// cuts ~1/dx bonds out of ~1/dx^2), so the table also gives broken bonds per metre of crack
// times dx, which is.
//
//   bench_convergence [--quick]      (--quick: the coarse pairs only, a few seconds)

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "app/Pipeline.h"
#include "app/Scene.h"
#include "sim/Membrane.h"

namespace {

using Clock = std::chrono::steady_clock;

struct Case {
    const char* scene;   ///< under scenes/
    int axis;            ///< the crack direction in rest coordinates: 0 x, 1 y
    double duration;     ///< simulated seconds, shortened where the scene's is longer than needed
    double sampleEvery;  ///< seconds between rows
    std::vector<double> dxs;
};

struct CrackState {
    double length = 0.0;  ///< extent of the broken bonds' midpoints along the axis
    double lo = 0.0, hi = 0.0;
    std::size_t broken = 0;  ///< notch included
    std::size_t grown = 0;   ///< broken after set-up
};

CrackState measure(const rend::sim::Membrane& m, int axis) {
    const auto& b = m.bonds();
    const auto& x0 = m.restPositions();
    CrackState s;
    s.lo = std::numeric_limits<double>::infinity();
    s.hi = -s.lo;
    for (int i = 0; i < m.particleCount(); ++i)
        for (int k = b.offsets[i]; k < b.offsets[i + 1]; ++k) {
            const int j = b.partners[k];
            if (j < i || m.damageState().bondAlive()[k])
                continue;  // each bond once, from its lower end
            const double mid = 0.5 * (x0[i][axis] + x0[j][axis]);
            s.lo = std::min(s.lo, mid);
            s.hi = std::max(s.hi, mid);
            ++s.broken;
        }
    s.length = s.broken ? s.hi - s.lo : 0.0;
    s.grown = s.broken - m.notchedBondCount();
    return s;
}

void runCase(const Case& c) {
    const std::string file = std::string(REND_SOURCE_DIR) + "/scenes/" + c.scene;
    for (double dx : c.dxs) {
        char dxText[32], durationText[48];
        std::snprintf(dxText, sizeof dxText, "sheet.dx=%g", dx);
        std::snprintf(durationText, sizeof durationText, "time.duration=%g", c.duration);
        const rend::Scene scene = rend::loadScene(file, {dxText, durationText});
        const auto start = Clock::now();
        rend::sim::Membrane m = rend::prepareMembrane(scene);
        // The pipeline's frame-aligned step, so both dx land on the same sample times.
        const auto [substeps, dt] = rend::substepsPerFrame(m.timeStep(), scene.sim.time.fps);
        m.setTimeStep(dt);
        const int frames = scene.frameCount();
        const int framesPerSample =
            std::max(1, int(std::lround(c.sampleEvery * scene.sim.time.fps)));
        std::printf("# %s dx=%g: %d particles, %zu bonds, R/dx=%g, dt=%.3g s (%d per frame)\n",
                    c.scene, dx, m.particleCount(), m.bondCount(), scene.sim.sheet.horizonFactor,
                    dt, substeps);
        try {
            for (int frame = 1; frame <= frames; ++frame) {
                for (int s = 0; s < substeps; ++s) m.step();
                if (frame % framesPerSample != 0 && frame != frames) continue;
                const CrackState cs = measure(m, c.axis);
                const double fraction = double(cs.broken) / double(m.bondCount());
                // Bonds cut per metre of crack, times dx: resolution-free for a straight crack.
                const double perLength = cs.length > 0 ? cs.broken / cs.length * dx : 0.0;
                std::printf("%-16s %6g %8d %6.2f %10.4f %8.4f %8.4f %9zu %9zu %11.3e %9.3f %8.1f\n",
                            c.scene, dx, m.particleCount(), m.time(), cs.length, cs.lo, cs.hi,
                            cs.broken, cs.grown, fraction, perLength,
                            std::chrono::duration<double>(Clock::now() - start).count());
                std::fflush(stdout);
            }
        } catch (const rend::sim::NumericalBlowUp& e) {
            std::printf("# %s dx=%g: blew up: %s\n", c.scene, dx, e.what());
        }
    }
}

}  // namespace

int main(int argc, char** argv) {
    const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
    // crack_path: the tear runs along +x from the notch tip at x = -0.3; dt = 1e-4 (Table 1) for
    // every dx. The scene's own dx is 0.02; its dx / 2 (46K particles, 50K steps) takes minutes.
    // foil_tear: the slit at the top edge tears downwards (-y); dt = 3e-4 (Table 1).
    const std::vector<Case> cases = {
        {"crack_path.toml", 0, quick ? 2.0 : 5.0, 1.0,
         quick ? std::vector<double>{0.04, 0.02} : std::vector<double>{0.04, 0.02, 0.01}},
        {"foil_tear.toml", 1, quick ? 4.0 : 16.0, 2.0, {0.04, 0.02}},
    };
    std::printf("%-16s %6s %8s %6s %10s %8s %8s %9s %9s %11s %9s %8s\n", "scene", "dx", "particles",
                "t", "crack_len", "from", "to", "broken", "grown", "broken_frac", "per_m*dx",
                "wall_s");
    const auto start = Clock::now();
    for (const Case& c : cases) runCase(c);
    std::printf("# total wall time %.1f s\n",
                std::chrono::duration<double>(Clock::now() - start).count());
    return 0;
}
