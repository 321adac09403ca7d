// Seed 004's particle level set of the outline (sim/ParticleLevelSet.h) under refinement: a
// disc (r = 0.1 m) at rest, after 200 steps. Error: the largest distance of the zero level set
// from the scene's circle, over r (marching triangles' chords: second order). The lattice
// surface's outline, its outermost particles, is the baseline (first order).

#include <algorithm>
#include <cmath>
#include <vector>

#include "bench/accuracy/Report.h"
#include "sim/Lattice.h"
#include "sim/Membrane.h"

namespace rend::bench {
namespace {

struct OutlineFigures {
    double levelSet, lattice;  ///< largest distance from the circle over r
};

OutlineFigures discOutline(double dx) {
    sim::MembraneParams p;
    p.sheet.outline = sim::Outline::Disc;
    p.sheet.radius = 0.1;
    p.sheet.dx = dx;
    p.particleLevelSet = true;
    sim::Membrane m(p);
    for (int s = 0; s < 200; ++s) m.step();
    const sim::FrameView v = m.view(1);
    const int n = int(v.particleCount());
    OutlineFigures f{0.0, 0.0};
    for (std::size_t t = 0; t < v.bandTriangles.size(); ++t)
        for (int i : v.bandTriangles[t])
            for (int g : v.bandTriangles[t]) {
                if (!v.bandKept[t] || i >= n || g < n) continue;
                const double s = v.levelSet[i] / (v.levelSet[i] - v.ghostLevelSet[g - n]);
                const Eigen::Vector3d z =
                    v.positions[i] + s * (v.ghostPositions[g - n] - v.positions[i]);
                f.levelSet = std::max(f.levelSet, std::abs(sim::outlineDistance(p.sheet, z)));
                // A particle of a band triangle is an outline particle of the lattice surface.
                f.lattice =
                    std::max(f.lattice, std::abs(sim::outlineDistance(p.sheet, v.positions[i])));
            }
    f.levelSet /= p.sheet.radius;
    f.lattice /= p.sheet.radius;
    return f;
}

void levelSetCase(Report& report) {
    Family level{"level_set", "disc outline, particle level set", {}, ""};
    Family lattice{"level_set", "disc outline, outermost particles", {}, ""};
    for (const double dx : {0.02, 0.01, 0.005, 0.0025}) {
        const auto start = Clock::now();
        const OutlineFigures f = discOutline(dx);
        const double seconds = secondsSince(start);
        const std::string label = "dx=" + fmt("%g", dx);
        level.points.push_back({label, seconds, f.levelSet});
        lattice.points.push_back({label, seconds, f.lattice});
        report.row(level, level.points.back());
        report.row(lattice, lattice.points.back());
    }
    level.why = "a chord of the circle across a band triangle, dx^2 / 8r";
    lattice.why = "the lattice rows miss the circle by up to a spacing";
    report.checkMonotone(level);
    report.checkMonotone(lattice);
}

const CaseRegistration kLevelSet{96, "level_set", &levelSetCase};

}  // namespace
}  // namespace rend::bench
