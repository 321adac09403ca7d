// The blow-up guard never stops a shipped scene: every scene with every solver that takes it,
// at the largest step rend picks itself (dt = "auto"), where the guard is closest to tripping.
// The full-length version of this check is in the README ("Blow-up guard").

#include <gtest/gtest.h>

#include <filesystem>

#include "app/Pipeline.h"
#include "app/Scene.h"
#include "app/SceneError.h"

using namespace rend;

TEST(GuardOnShippedScenes, EverySceneWithEverySolverAtTheAutoStepRunsUntripped) {
    const std::filesystem::path dir = std::filesystem::path(REND_SOURCE_DIR) / "scenes";
    int runs = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        if (entry.path().extension() != ".toml") continue;
        for (const char* solver :
             {"peridynamic", "fem_cst", "mass_spring_vg", "mass_spring_tp", "sph"}) {
            Scene scene;
            try {
                scene = loadScene(entry.path(), {std::string("solver=") + solver, "time.dt=auto"});
            } catch (const SceneError&) {
                continue;  // a solver that does not take this scene
            }
            sim::Membrane m = prepareMembrane(scene);
            // A quarter of a second: ramps, sources and notches have started to act.
            const int steps = int(0.25 / m.timeStep()) + 1;
            try {
                for (int s = 0; s < steps; ++s) m.step();
            } catch (const sim::NumericalBlowUp& e) {
                ADD_FAILURE() << entry.path().filename() << " with " << solver << ": " << e.what();
            }
            ++runs;
        }
    }
    EXPECT_GE(runs, 60);
}
