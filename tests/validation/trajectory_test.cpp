// The membrane paper's SPH comparison (Sec. 6.1, Fig. 9) between our own solvers: the large-
// stretching scene, coarsened to dx = 0.04 and 2 s, run by the FEM and by the kernel-corrected
// SPH, which share the continuum law (St. Venant-Kirchhoff, nu = 0.3) and differ only in how
// they discretise it. The particles at P1 (0.64, 0.84) and P2 (1.64, 1.64) must follow the same
// paths. bench_trajectories runs the full scene with every solver.

#include <gtest/gtest.h>

#include <cstdio>

#include "app/Pipeline.h"
#include "app/Scene.h"

namespace {

struct Path {
    std::vector<Eigen::Vector2d> p1, p2;
};

Path run(const char* solver) {
    const rend::Scene scene = rend::loadScene(
        REND_SOURCE_DIR "/scenes/stretch.toml",
        {std::string("solver=") + solver, "sheet.dx=0.04", "time.duration=2", "time.dt=auto"});
    rend::sim::Membrane m = rend::prepareMembrane(scene);
    const auto [substeps, dt] = rend::substepsPerFrame(m.timeStep(), scene.sim.time.fps);
    m.setTimeStep(dt);
    const int p1 = m.nearestParticle({-0.36, -0.16}), p2 = m.nearestParticle({0.64, 0.64});
    Path path;
    for (int frame = 1; frame <= scene.frameCount(); ++frame) {
        for (int s = 0; s < substeps; ++s) m.step();
        path.p1.push_back(m.positions()[p1].head<2>());
        path.p2.push_back(m.positions()[p2].head<2>());
    }
    return path;
}

}  // namespace

TEST(ValidationTrajectory, SphAndFemFollowTheSamePathsInTheLargeStretchingScene) {
    const Path fem = run("fem_cst"), sph = run("sph");
    double apart = 0.0, travelled = 0.0;
    for (std::size_t k = 0; k < fem.p1.size(); ++k) {
        apart = std::max({apart, (fem.p1[k] - sph.p1[k]).norm(), (fem.p2[k] - sph.p2[k]).norm()});
        travelled = std::max(
            {travelled, (fem.p1[k] - fem.p1.front()).norm(), (fem.p2[k] - fem.p2.front()).norm()});
    }
    std::printf(
        "[trajectory] fem_cst against sph over 2 s: largest distance %.4f m, %.2f%% of the "
        "%.3f m travelled\n",
        apart, 100 * apart / travelled, travelled);
    EXPECT_GT(travelled, 0.1);
    EXPECT_LT(apart, 0.05 * travelled);
}
