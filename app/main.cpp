// The `rend` command: thin over rend_app. Only main turns errors into messages and exit
// statuses: 2 for bad input, 3 for a numerical blow-up, 1 for anything else.

#include <omp.h>
#include <toml++/toml.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <thread>

#include "app/FrameSelection.h"
#include "app/MpiDomain.h"
#include "app/Pipeline.h"
#include "app/Scene.h"
#include "app/SceneError.h"
#include "app/SceneNames.h"
#include "app/Threads.h"
#include "render/SheetVolume.h"
#include "render/SplatSurface.h"
#include "render/Versions.h"
#include "sim/SolverRegistry.h"

namespace {

void printVersions() {
    std::printf("rend %s\n", REND_VERSION);
    std::printf("  %-10s %d.%d.%d\n", "Eigen", EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION,
                EIGEN_MINOR_VERSION);
    std::printf("  %-10s spec %d, %d threads, %d cores usable\n", "OpenMP", _OPENMP,
                omp_get_max_threads(), rend::usableCores());
    std::printf("  %-10s %d.%d.%d\n", "toml++", TOML_LIB_MAJOR, TOML_LIB_MINOR, TOML_LIB_PATCH);
    std::printf("  %-10s %s\n", "CLI11", CLI11_VERSION);
    std::printf("  %-10s %s\n", "MPI", rend::mpiVersion().c_str());
    for (const auto& [name, version] : rend::render::renderLibraryVersions())
        std::printf("  %-10s %s\n", name.c_str(), version.c_str());
}

/// --quality is [sheet] quality given last, so it wins over the file and every --set.
std::vector<std::string> withQuality(std::vector<std::string> sets, const std::string& quality) {
    if (!quality.empty()) sets.push_back("sheet.quality=" + quality);
    return sets;
}

/// The exported VDB's voxel, the thickness it holds, and its size; with the voxel that holds
/// the sheet's own thickness when that is another.
void printVolumeEstimate(const rend::Scene& scene, const rend::sim::Membrane& membrane) {
    const rend::sim::FrameView rest = membrane.view(0);
    double area = 0.0;
    for (const auto& t : rest.restTriangles)
        area += 0.5 * (rest.restPositions[t[1]] - rest.restPositions[t[0]])
                          .cross(rest.restPositions[t[2]] - rest.restPositions[t[0]])
                          .norm();
    const double h = scene.sim.sheet.thickness;
    const auto line = [&](const char* what, double voxel) {
        const double voxels = rend::render::sheetVolumeVoxels(area, voxel, h);
        std::printf("  vdb%s: voxel %.3g m, %.3g m thick, about %.3g M voxels, %.3g MB a frame\n",
                    what, voxel, rend::render::sheetVolumeThickness(h, voxel), voxels / 1e6,
                    voxels * rend::render::kSheetVolumeBytesPerVoxel / 1e6);
    };
    const double voxel = scene.render.vdb.voxelSize > 0.0 ? scene.render.vdb.voxelSize
                                                          : 0.5 * rend::render::restSpacing(rest);
    line("", voxel);
    if (voxel > 0.5 * h) line(" at the sheet's thickness (render.vdb_voxel_size = h / 2)", 0.5 * h);
}

int checkCommand(const std::string& file, const std::vector<std::string>& sets,
                 const std::string& quality) {
    const rend::Scene scene = rend::loadScene(file, withQuality(sets, quality));
    const rend::sim::Membrane membrane = rend::prepareMembrane(scene);
    const auto [substeps, dt] = rend::substepsPerFrame(membrane.timeStep(), scene.sim.time.fps);
    const rend::RunEstimate estimate = rend::estimateRun(scene, membrane);
    const rend::SheetEstimate sheet = rend::estimateSheet(scene.sim.sheet);
    const bool adaptive = scene.sim.time.adaptive();  // steps of at most dt, more where needed
    std::printf(
        "%s: ok (quality %s, dx %.4g m)\n  %d particles, %zu bonds, dt %s%.4g s (stable limit "
        "%.4g s), %s%d steps per frame, %d frames\n"
        "  estimated memory %.3g GB (%.3g particles x (%g B + %.3g bonds x %g B))\n"
        "  estimated cost: %s\n"
        "  cache (rend run --cache-every 1): %.3g MB a frame before compression, at most %.3g GB "
        "for %d frames\n",
        file.c_str(), std::string(rend::names::kQualities[std::size_t(scene.quality)]).c_str(),
        scene.sim.sheet.dx, membrane.particleCount(), membrane.bondCount(),
        adaptive ? "adaptive, at most " : "", dt, membrane.stableTimeStep(),
        adaptive ? "at least " : "", substeps, scene.frameCount(), sheet.bytes / 1e9,
        sheet.particles, rend::SheetEstimate::kBytesPerParticle, sheet.bondsPerParticle,
        rend::SheetEstimate::kBytesPerBondEnd, rend::describeEstimate(estimate).c_str(),
        double(rend::cacheFrameBytes(membrane)) / 1e6,
        double(rend::cacheFrameBytes(membrane)) * scene.frameCount() / 1e9, scene.frameCount());
    if (std::ranges::count(scene.exports, rend::ExportFormat::Vdb))
        printVolumeEstimate(scene, membrane);
    return 0;
}

/// "a, b, c" for messages.
std::string namesText(std::span<const std::string_view> names) {
    std::string text;
    for (std::string_view name : names) text += (text.empty() ? "" : ", ") + std::string(name);
    return text;
}

/// CLI11's IsMember takes a container of strings.
std::vector<std::string> members(std::span<const std::string_view> names) {
    return {names.begin(), names.end()};
}

struct RunArgs {
    std::string scene, out = "out", frames, renderer, surface, exports, quality, chunk;
    std::vector<std::string> sets;
    int threads = 0;
    int spp = 0;
    int cacheEvery = 1;
    bool resume = false, skipExisting = false;
};

std::vector<rend::ExportFormat> parseExports(const std::string& text) {
    std::vector<rend::ExportFormat> formats;
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t end = std::min(text.find(',', start), text.size());
        const std::string name = text.substr(start, end - start);
        const auto index = rend::names::indexOf(rend::names::kExportFormats, name);
        if (!index)
            throw rend::SceneError("--export " + text +
                                   ": error: expected a comma-separated list of " +
                                   namesText(rend::names::kExportFormats) + ", found \"" + name +
                                   "\". Use e.g. --export ply,vdb.");
        formats.push_back(rend::ExportFormat(*index));
        start = end + 1;
    }
    return formats;
}

// Command-line choices override the scene's, after it has been validated.
void applyOverrides(const RunArgs& a, rend::Scene& scene) {
    using rend::names::indexOf;
    if (auto k = indexOf(rend::names::kRenderers, a.renderer))
        scene.renderer = rend::RendererKind(*k);
    if (auto k = indexOf(rend::names::kSurfaces, a.surface))
        scene.render.surface = rend::render::SurfaceKind(*k);
    if (!a.exports.empty()) scene.exports = parseExports(a.exports);
    if (a.spp > 0) scene.render.pathTracing.samplesPerPixel = a.spp;
}

/// --threads, else OMP_NUM_THREADS, else the cores this process may use (affinity and cgroup
/// quota), which OpenMP's own default does not look at.
void setThreads(int threads) {
    if (threads > 0)
        omp_set_num_threads(threads);
    else if (std::getenv("OMP_NUM_THREADS") == nullptr)
        omp_set_num_threads(rend::usableCores());
}

int runCommand(const RunArgs& a) {
    setThreads(a.threads);
    rend::Scene scene = rend::loadScene(a.scene, withQuality(a.sets, a.quality));
    applyOverrides(a, scene);
    rend::RunOptions options;
    options.outDir = a.out;
    if (std::filesystem::exists(options.outDir) && !std::filesystem::is_directory(options.outDir))
        throw rend::SceneError("--out " + a.out +
                               ": error: expected an output folder, found a file. Use another "
                               "--out, or move the file away.");
    if (!a.frames.empty()) options.frames = rend::parseFrameList(a.frames, scene.frameCount());
    options.progressBar = isatty(STDERR_FILENO);
    options.cacheEvery = a.cacheEvery;
    options.resume = a.resume;
    options.followLoad = a.threads <= 0 && std::getenv("OMP_NUM_THREADS") == nullptr;
    const rend::RunSummary s = rend::runScene(scene, options);
    if (rend::processRank() != 0) return 0;  // the first process reports
    std::printf(
        "wrote %s: %d frames (%d images), %d particles, %zu bonds, %ld steps of %.4g s, "
        "%.1f ns per particle-step\n",
        a.out.c_str(), s.framesSimulated, s.framesWritten, s.particles, s.bonds, s.steps, s.dt,
        s.nsPerParticleStep);
    return 0;
}

int renderCommand(const RunArgs& a) {
    setThreads(a.threads);
    auto [file, sets] = rend::cacheSource(a.out);
    sets.insert(sets.end(), a.sets.begin(), a.sets.end());  // the look may change; not the sim
    rend::Scene scene = rend::loadScene(file, sets);
    applyOverrides(a, scene);
    rend::RenderOptions options;
    options.outDir = a.out;
    if (!a.frames.empty()) options.frames = rend::parseFrameList(a.frames, scene.frameCount());
    if (!a.chunk.empty()) {
        if (options.frames.empty())
            for (int frame = 1; frame <= scene.frameCount(); ++frame)
                options.frames.push_back(frame);
        options.frames = rend::chunkOf(options.frames, a.chunk);
        if (options.frames.empty()) {
            std::printf("rendered nothing from %s: chunk %s holds no frame\n", a.out.c_str(),
                        a.chunk.c_str());
            return 0;
        }
    }
    options.skipExisting = a.skipExisting;
    options.progressBar = isatty(STDERR_FILENO);
    const rend::RenderSummary r = rend::renderFromCache(scene, options);
    std::printf("rendered %d frames from the cache in %s (%d skipped, already there)\n",
                r.framesWritten, a.out.c_str(), r.framesSkipped);
    return 0;
}

/// --quality takes preview or final; anything else is bad input (exit 2) that names both.
CLI::Validator qualityValidator() {
    return CLI::Validator(
        [](std::string& value) {
            if (rend::names::indexOf(rend::names::kQualities, value)) return std::string();
            return "expected " + namesText(rend::names::kQualities) + ", found \"" + value +
                   "\". Use e.g. --quality final.";
        },
        "preview|final");
}

/// CLI11 stores `--frames ''` as an empty string, which reads like an absent option; an empty
/// value is never what the user meant, so it is refused instead.
CLI::Validator nonEmpty(const std::string& expected, const std::string& example) {
    return CLI::Validator(
        [=](std::string& value) {
            return value.empty() ? "expected " + expected + ", found an empty value. Use e.g. " +
                                       example + "."
                                 : std::string();
        },
        "");
}

/// The options rend run and rend render share: what is drawn and exported, and the threads.
void addOutputOptions(CLI::App* command, RunArgs& a) {
    command->add_option("--renderer", a.renderer, "Override [render] renderer")
        ->check(CLI::IsMember(members(rend::names::kRenderers)));
    command->add_option("--surface", a.surface, "Override [render] surface")
        ->check(CLI::IsMember(members(rend::names::kSurfaces)));
    command->add_option("--export", a.exports, "Per-frame exports, e.g. ply,obj,glb,vdb")
        ->check(nonEmpty("a list of ply, obj, glb, vdb", "--export ply,vdb"));
    command->add_option("--spp", a.spp, "Path-traced samples per pixel (embree)")
        ->check(CLI::Range(1, 4096));
    command
        ->add_option("--threads", a.threads,
                     "OpenMP threads (default: OMP_NUM_THREADS, else the cores this process "
                     "may use)")
        ->check(CLI::Range(1, 1024));
}

// The solvers a scene can name, from the registry, for `rend --help` and `rend run --help`.
std::string solverHelp() {
    std::string out = "Solvers (solver = \"NAME\" in a scene, or --set solver=NAME):\n";
    for (const rend::sim::SolverEntry& e : rend::sim::solverRegistry())
        out += "  " + std::string(e.name) + std::string(16 - e.name.size(), ' ') +
               std::string(e.model) + "\n";
    return out;
}

}  // namespace

int runMain(int argc, char** argv);

// Several processes under mpirun (app/MpiDomain.h): only the first reports an error, and one
// that fails ends them all.
int main(int argc, char** argv) {
    int code = 0;
    try {
        const int processes = rend::startProcesses(argc, argv);
        if (processes > 1 && rend::processRank() != 0) std::freopen("/dev/null", "w", stderr);
        code = runMain(argc, argv);
        // Errors in the scene reach every process at once: the first reports it before the
        // others end the run, or they would kill it mid-message.
        if (code != 0 && processes > 1 && rend::processRank() != 0)
            std::this_thread::sleep_for(std::chrono::seconds(2));
        if (code != 0 && processes > 1) rend::abortProcesses(code);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
    rend::endProcesses();
    return code;
}

int runMain(int argc, char** argv) {
    CLI::App app{"rend: thin membranes that stretch, wrinkle and tear, rendered to PNG"};
    app.require_subcommand(0, 1);
    bool version = false;
    app.add_flag("--version", version, "Print the versions of rend and every library in use");
    app.footer(solverHelp());

    RunArgs run;
    CLI::App* runCmd = app.add_subcommand("run", "Simulate a scene and write its outputs");
    const CLI::Validator sceneFile = nonEmpty("a scene file", "scenes/stretch.toml");
    const CLI::Validator quality = qualityValidator();
    const std::string qualityHelp =
        "Override [sheet] quality: preview (at dx) or final (dx_final, else >= 250,000 "
        "particles)";
    runCmd->add_option("scene", run.scene, "Scene file (TOML)")->required()->check(sceneFile);
    runCmd->add_option("--out", run.out, "Output folder")
        ->capture_default_str()
        ->check(nonEmpty("an output folder", "--out out/stretch"));
    const std::string framesHelp =
        "Frames to write: N, FIRST-LAST, FIRST-LAST:STEP, or a comma list";
    runCmd->add_option("--frames", run.frames, framesHelp)
        ->check(nonEmpty("N or FIRST-LAST", "--frames 1-10 (or leave --frames out for all)"));
    addOutputOptions(runCmd, run);
    runCmd->add_option("--quality", run.quality, qualityHelp)->check(quality);
    runCmd->add_option("--set", run.sets, "Override a scene value: key.path=value (repeatable)");
    runCmd
        ->add_option("--cache-every", run.cacheEvery,
                     "Cache every N-th frame's state in OUT/cache (0: no cache)")
        ->capture_default_str()
        ->check(CLI::Range(0, 1000000));
    runCmd->add_flag("--resume", run.resume,
                     "Continue from the last complete cached frame in --out (after a kill)");
    runCmd->footer(solverHelp());

    RunArgs render;
    CLI::App* renderCmd = app.add_subcommand(
        "render", "Render and export frames from a run's cache, without simulating");
    renderCmd->add_option("out", render.out, "The output folder of a rend run, with its cache")
        ->required()
        ->check(nonEmpty("an output folder", "out/stretch"));
    renderCmd->add_option("--frames", render.frames, framesHelp + " (default: every cached one)")
        ->check(nonEmpty("a frame list", "--frames 1-10,20,30-40:2"));
    renderCmd
        ->add_option("--chunk", render.chunk,
                     "K/N: the K-th of N contiguous chunks of the frames (a job array)")
        ->check(nonEmpty("K/N", "--chunk 1/4"));
    renderCmd->add_flag("--skip-existing", render.skipExisting,
                        "Leave frames whose every file is already there");
    addOutputOptions(renderCmd, render);
    renderCmd->add_option("--set", render.sets,
                          "Override a [render], [camera], [light] or [output] value");

    std::string checkScene, checkQuality;
    std::vector<std::string> checkSets;
    CLI::App* checkCmd = app.add_subcommand("check", "Parse and validate a scene, write nothing");
    checkCmd->add_option("scene", checkScene, "Scene file (TOML)")->required()->check(sceneFile);
    checkCmd->add_option("--quality", checkQuality, qualityHelp)->check(quality);
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
        if (*renderCmd) return renderCommand(render);
        if (*checkCmd) return checkCommand(checkScene, checkSets, checkQuality);
        std::cout << app.help();
        return 2;
    } catch (const rend::SceneError& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 2;
    } catch (const rend::sim::NumericalBlowUp& e) {
        std::fprintf(stderr, "%s\n", e.what());  // located by the pipeline
        return 3;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
}
