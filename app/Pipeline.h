#pragma once
// `rend run` and `rend check`: scene -> Membrane -> FrameView -> surface -> renderer -> PNG,
// plus stats.csv and run.json. Stages run only when an output needs them.

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>

#include "app/Scene.h"
#include "render/SheetVolume.h"
#include "sim/Membrane.h"

namespace rend {

struct RunOptions {
    std::filesystem::path outDir = "out";
    std::vector<int> frames;   ///< the frames to write, ascending; empty: all
    bool progressBar = false;  ///< redraw one line; else one line per frame
    /// Cache every N-th frame's state (cache/frame_N.rcache, app/Cache.h); 0: none.
    int cacheEvery = 1;
    /// Continue from the last complete cached frame in outDir (rend run --resume).
    bool resume = false;
    /// The thread count follows the machine's load frame by frame (app/Threads.h's
    /// ThreadGovernor): the default, unless --threads or OMP_NUM_THREADS fixes it.
    bool followLoad = false;
};

/// Wall seconds per stage of a run.
struct StageTimes {
    double setup = 0.0;
    double simulate = 0.0;
    double contact = 0.0;       ///< of simulate: ground, colliders and self-contact
    double contactLists = 0.0;  ///< of contact: the self-contact's candidate-list builds
    double surface = 0.0;
    double render = 0.0;
    double write = 0.0;
    double cache = 0.0;  ///< writing the cache's frames
};

struct RunSummary {
    int particles = 0;
    std::size_t bonds = 0;
    std::string stepControl;  ///< "fixed", "auto" or "adaptive"
    double dt = 0.0;          ///< the fixed step, or the adaptive steps' mean
    double dtMin = 0.0, dtMax = 0.0;
    double stableDt = 0.0;
    int substeps = 0;  ///< explicit steps per frame; 0 for adaptive steps
    /// Adaptive: steps each limit chose (bound, stretch, burst, growth; sim::StepLimit order).
    std::array<long, 4> limitedBy{};
    std::size_t largestBurst = 0;  ///< adaptive: the most bonds one step broke
    long steps = 0;
    long extraSubsteps = 0;      ///< pieces the power law's stiffening cut steps into, beyond steps
    long contactListBuilds = 0;  ///< the self-contact's candidate-list builds
    int framesSimulated = 0;
    int framesWritten = 0;
    int resumedAfter = 0;            ///< the cached frame a --resume continued from; 0: none
    int framesCached = 0;            ///< cache files this run wrote
    std::uintmax_t cacheBytes = 0;   ///< their bytes
    render::SheetVolumeInfo volume;  ///< the exported VDB's voxel and thickness; zeros: none
    StageTimes seconds;
    double nsPerParticleStep = 0.0;
};

/// What a run will cost, estimated before it starts (conservative figures for one core).
struct RunEstimate {
    int frames = 0;
    double particles = 0;
    double bonds = 0;
    double stepsPerFrame = 0;
    double diffusionSubsteps = 0;  ///< per explicit step; 0 without diffusion
    double particleSteps = 0;
    double bondSteps = 0;  ///< bond ends visited, over the whole run
    double seconds = 0;    ///< on one core
    double diffusionSeconds = 0;
    double bytes = 0;  ///< estimateSheet's memory
};

RunEstimate estimateRun(const Scene& scene, const sim::Membrane& membrane);
/// "50000 steps (417 per frame x 120 frames), ...: about 3.5 min on one core".
std::string describeEstimate(const RunEstimate& estimate);

/// Builds the membrane and checks what only a built membrane can tell (dt against the stable
/// bound, boundary regions that claim no particle, notches that cut nothing, the estimated cost
/// against its limit). Throws SceneError located at the key that caused it. Writes nothing.
sim::Membrane prepareMembrane(const Scene& scene);

/// Steps per frame and the dt that lands frames exactly on k / fps, never above `dt`.
std::pair<int, double> substepsPerFrame(double dt, double fps);

/// Runs the scene into options.outDir. Throws SceneError before anything is written, and
/// sim::NumericalBlowUp after finishing stats.csv and run.json up to the failing frame.
RunSummary runScene(const Scene& scene, const RunOptions& options);

struct RenderOptions {
    std::filesystem::path outDir = "out";  ///< a rend run's folder, with its cache
    std::vector<int> frames;               ///< ascending; empty: every cached frame
    bool skipExisting = false;  ///< leave frames whose every file is there (a farm's retry)
    bool progressBar = false;
};

struct RenderSummary {
    int framesWritten = 0, framesSkipped = 0;
    StageTimes seconds;  ///< setup, cache reads (as simulate), surface, render, write
};

/// rend render: writes the frames and exports of `scene` from the cache in options.outDir,
/// without simulating. Throws CacheError (a SceneError) naming a missing, damaged or foreign
/// cache file; frames before it stay written.
RenderSummary renderFromCache(const Scene& scene, const RenderOptions& options);

/// The scene file and --set values a run's cache was written with (cache/source.toml); throws
/// SceneError when the folder holds no cache.
std::pair<std::filesystem::path, std::vector<std::string>> cacheSource(
    const std::filesystem::path& outDir);

/// The state bytes one cached frame holds before compression (the membrane at set-up; the
/// same at every frame but for a fixed-step run's missing forces).
std::uintmax_t cacheFrameBytes(const sim::Membrane& membrane);

}  // namespace rend
