// The `rend` command: thin over rend_app. Only main turns errors into messages and exit
// statuses: 2 for bad input, 3 for a numerical blow-up, 1 for anything else.

#include <omp.h>
#include <toml++/toml.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <cstdio>
#include <iostream>

#include "app/Pipeline.h"
#include "app/Scene.h"
#include "app/SceneError.h"
#include "render/Versions.h"

namespace {

void printVersions() {
    std::printf("rend %s\n", REND_VERSION);
    std::printf("  %-10s %d.%d.%d\n", "Eigen", EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION,
                EIGEN_MINOR_VERSION);
    std::printf("  %-10s spec %d, %d threads\n", "OpenMP", _OPENMP, omp_get_max_threads());
    std::printf("  %-10s %d.%d.%d\n", "toml++", TOML_LIB_MAJOR, TOML_LIB_MINOR, TOML_LIB_PATCH);
    std::printf("  %-10s %s\n", "CLI11", CLI11_VERSION);
    for (const auto& [name, version] : rend::render::renderLibraryVersions())
        std::printf("  %-10s %s\n", name.c_str(), version.c_str());
}

int checkCommand(const std::string& file, const std::vector<std::string>& sets) {
    const rend::Scene scene = rend::loadScene(file, sets);
    const rend::sim::Membrane membrane = rend::prepareMembrane(scene);
    const auto [substeps, dt] = rend::substepsPerFrame(membrane.timeStep(), scene.sim.time.fps);
    std::printf(
        "%s: ok\n  %d particles, %zu bonds, dt %.4g s (stable limit %.4g s), "
        "%d steps per frame, %d frames\n",
        file.c_str(), membrane.particleCount(), membrane.bondCount(), dt, membrane.stableTimeStep(),
        substeps, scene.frameCount());
    return 0;
}

struct RunArgs {
    std::string scene, out = "out", frames, renderer;
    std::vector<std::string> sets;
    int threads = 0;
};

int runCommand(const RunArgs& a) {
    if (a.threads > 0) omp_set_num_threads(a.threads);
    const rend::Scene scene = rend::loadScene(a.scene, a.sets);
    rend::RunOptions options;
    options.outDir = a.out;
    if (!a.frames.empty()) options.frames = rend::parseFrameRange(a.frames, scene.frameCount());
    if (a.renderer == "none") options.renderer = rend::RendererKind::None;
    if (a.renderer == "osmesa") options.renderer = rend::RendererKind::Osmesa;
    options.progressBar = isatty(STDERR_FILENO);
    const rend::RunSummary s = rend::runScene(scene, options);
    std::printf(
        "wrote %s: %d frames (%d images), %d particles, %zu bonds, %ld steps of %.4g s, "
        "%.1f ns per particle-step\n",
        a.out.c_str(), s.framesSimulated, s.framesWritten, s.particles, s.bonds, s.steps, s.dt,
        s.nsPerParticleStep);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"rend: thin membranes that stretch, wrinkle and tear, rendered to PNG"};
    app.require_subcommand(0, 1);
    bool version = false;
    app.add_flag("--version", version, "Print the versions of rend and every library in use");

    RunArgs run;
    CLI::App* runCmd = app.add_subcommand("run", "Simulate a scene and write its outputs");
    runCmd->add_option("scene", run.scene, "Scene file (TOML)")->required();
    runCmd->add_option("--out", run.out, "Output folder")->capture_default_str();
    runCmd->add_option("--frames", run.frames, "Frames to write: N or FIRST-LAST");
    runCmd->add_option("--renderer", run.renderer, "Override [render] renderer")
        ->check(CLI::IsMember({"osmesa", "none"}));
    runCmd->add_option("--threads", run.threads, "OpenMP threads (default: all cores)")
        ->check(CLI::Range(1, 1024));
    runCmd->add_option("--set", run.sets, "Override a scene value: key.path=value (repeatable)");

    std::string checkScene;
    std::vector<std::string> checkSets;
    CLI::App* checkCmd = app.add_subcommand("check", "Parse and validate a scene, write nothing");
    checkCmd->add_option("scene", checkScene, "Scene file (TOML)")->required();
    checkCmd->add_option("--set", checkSets, "Override a scene value: key.path=value");

    try {
        app.parse(argc, argv);
    } catch (const CLI::Success& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        app.exit(e);
        return 2;
    }
    try {
        if (version) return printVersions(), 0;
        if (*runCmd) return runCommand(run);
        if (*checkCmd) return checkCommand(checkScene, checkSets);
        std::cout << app.help();
        return 2;
    } catch (const rend::SceneError& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 2;
    } catch (const rend::sim::NumericalBlowUp& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 3;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
}
