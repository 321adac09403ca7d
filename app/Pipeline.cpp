#include "app/Pipeline.h"

#include <omp.h>
#include <toml++/toml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

#include "app/Cache.h"
#include "app/CacheWriter.h"
#include "app/FrameWriter.h"
#include "app/MpiDomain.h"
#include "app/Outputs.h"
#include "app/SceneError.h"
#include "app/Threads.h"
#include "render/AtomicFile.h"

namespace rend {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

void checkTimeStep(const Scene& scene, const sim::Membrane& membrane) {
    const auto& t = scene.sim.time;
    if (!t.dt || t.allowUnstable || *t.dt <= membrane.stableTimeStep() * (1.0 + 1e-12)) return;
    const auto& m = scene.sim.material;
    std::ostringstream msg;
    msg << scene.locationOf("time.dt") << ": error: time.dt: expected at most the stable limit "
        << membrane.stableTimeStep() << " s for E=" << m.youngsModulus << " Pa, rho=" << m.density
        << " kg/m^3, dx=" << scene.sim.sheet.dx << " m (Silling-Askari bound), found " << *t.dt
        << ". Use dt <= " << t.safety * membrane.stableTimeStep() << " or dt = \"auto\".";
    throw SceneError(msg.str());
}

/// Where a region was given: its box or edge, else the entry.
std::string regionLocation(const Scene& scene, const std::string& entry) {
    for (const char* key : {".box", ".edge"}) {
        if (scene.locations.contains(entry + key)) return scene.locationOf(entry + key);
    }
    return scene.locationOf(entry);
}

void checkBoundaries(const Scene& scene, const sim::Membrane& membrane) {
    const std::vector<int> counts = membrane.boundaryParticleCounts();
    for (std::size_t k = 0; k < counts.size(); ++k) {
        if (counts[k] != 0) continue;
        const std::string entry = "boundary." + std::to_string(k);
        throw SceneError(regionLocation(scene, entry) + ": error: " + entry +
                         ": expected a region that holds particles, found none inside it. "
                         "Widen its depth or box, or check it against the sheet's size.");
    }
}

/// Notches that lie on the sheet's bounding box but between particles (or in a disc's corner)
/// cut nothing; the loader already refused those off the sheet.
void checkNotches(const Scene& scene, const sim::Membrane& membrane) {
    if (scene.sim.notches.empty() || membrane.notchedBondCount() > 0) return;
    throw SceneError(scene.locationOf("notch.0.points") +
                     ": error: notch.0.points: expected notches that cross at least one bond, "
                     "found none crossed. Extend the polyline across the sheet's particles.");
}

// Conservative costs per explicit step, from run.json's ns_per_particle_step on one core
// (47 ns with 3 bonds per particle, 306 ns with 17, the SPH 300 ns), rounded up.
constexpr double kNsPerParticle = 300;
constexpr double kNsPerBondEnd = 10;
/// Diffusion sub-steps visit each bond once more and each particle's source list.
constexpr double kNsPerDiffusionParticle = 20;
/// Runs estimated beyond this many seconds on one core are refused unless allow_slow.
constexpr double kMaxEstimatedSeconds = 6 * 3600;
/// Beyond these, counters overflow (int steps per frame, int diffusion sub-steps, long steps).
constexpr double kMaxStepsPerFrame = 1e9;
constexpr double kMaxTotalSteps = 1e15;

/// Three digits; beyond 1e30 the figure only says "absurd", and never prints inf.
std::string roundedText(double value) {
    if (!(value <= 1e30)) return "over 1e30";
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", value);
    return text;
}

std::string durationText(double seconds) {
    if (seconds < 120) return roundedText(seconds) + " s";
    if (seconds < 7200) return roundedText(seconds / 60) + " min";
    if (!(seconds <= 3.6e15)) return "over 1e12 h";
    return roundedText(seconds / 3600) + " h";
}

/// The key whose value drives the estimate furthest from an ordinary run.
std::string costDriver(const Scene& scene, const RunEstimate& e) {
    if (e.diffusionSeconds > e.seconds - e.diffusionSeconds) return "material.conductivity";
    const double steps = e.stepsPerFrame / 1e3, particles = e.particles / 1e5,
                 frames = e.frames / 1e3;
    if (particles >= steps && particles >= frames) return "sheet.dx";
    if (frames >= steps) return "time.duration";
    return scene.sim.time.dt ? "time.dt" : "material.density";
}

void checkCost(const Scene& scene, const RunEstimate& e) {
    const bool impossible = e.stepsPerFrame > kMaxStepsPerFrame ||
                            e.diffusionSubsteps > kMaxStepsPerFrame ||
                            e.stepsPerFrame * e.frames > kMaxTotalSteps;
    if (!impossible && (e.seconds <= kMaxEstimatedSeconds || scene.allowSlow)) return;
    const std::string key = costDriver(scene, e);
    const std::string expected =
        impossible
            ? "at most 1e9 steps per frame, 1e9 diffusion sub-steps per step and 1e15 "
              "steps in all"
            : "a run estimated within " + durationText(kMaxEstimatedSeconds) + " on one core";
    const std::string fix =
        impossible ? "Raise dt or lower the material's stiffness-to-density ratio, conductivity "
                     "or the duration."
                   : "Coarsen dx, shorten the duration, raise dt or lower conductivity, or run "
                     "anyway with --set time.allow_slow=true.";
    throw SceneError(scene.locationOf(key) + ": error: " + key + ": expected " + expected +
                     ", found " + describeEstimate(e) + ". " + fix);
}

class Progress {
public:
    Progress(bool bar, int frames) : bar_(bar), frames_(frames), start_(Clock::now()) {}

    void frameDone(int frame, double time, const std::string& wrote) {
        const double elapsed = secondsSince(start_);
        if (!bar_) {
            std::fprintf(stderr, "frame %d/%d  t=%.4f s  %.1f s elapsed%s%s\n", frame, frames_,
                         time, elapsed, wrote.empty() ? "" : "  wrote ", wrote.c_str());
            return;
        }
        const int width = 30, filled = width * frame / frames_;
        const double eta = elapsed / frame * (frames_ - frame);
        std::fprintf(stderr, "\r[%s%s] %d/%d frames  %.1f s, ETA %.1f s ",
                     std::string(filled, '#').c_str(), std::string(width - filled, ' ').c_str(),
                     frame, frames_, elapsed, eta);
        if (frame == frames_) std::fputc('\n', stderr);
    }

private:
    bool bar_;
    int frames_;
    Clock::time_point start_;
};

// FNV-1a over the raw bytes of the final state: equal hashes mean bit-identical simulations,
// which is how a test shows that rendering never changes the physics.
std::string stateHash(const sim::Membrane& m) {
    std::uint64_t h = 0xcbf29ce484222325ULL;
    auto mix = [&](const void* data, std::size_t bytes) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (std::size_t k = 0; k < bytes; ++k) h = (h ^ p[k]) * 0x100000001b3ULL;
    };
    mix(m.positions().data(), m.positions().size() * sizeof(Eigen::Vector3d));
    mix(m.velocities().data(), m.velocities().size() * sizeof(Eigen::Vector3d));
    mix(m.theta().data(), m.theta().size() * sizeof(double));
    mix(m.damageState().bondAlive().data(), m.damageState().bondAlive().size());
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
    return hex;
}

// The exported volume's resolution and the thickness it holds (null without --export vdb).
std::string volumeJson(const render::SheetVolumeInfo& v, double sheetThickness) {
    if (v.voxelSize == 0.0) return "null";
    std::ostringstream j;
    j.precision(10);
    j << "{\"voxel_size\": " << v.voxelSize << ", \"thickness\": " << v.thickness
      << ", \"sheet_thickness\": " << sheetThickness << "}";
    return j.str();
}

std::string runJson(const Scene& scene, const RunSummary& s, const std::string& status,
                    const std::string& hash, const std::vector<std::string>& files) {
    std::ostringstream j;
    j.precision(10);
    j << "{\n  \"rend_version\": " << jsonString(REND_VERSION) << ",\n"
      << "  \"scene\": " << jsonString(scene.file.string()) << ",\n"
      << "  \"status\": " << jsonString(status) << ",\n"
      << "  \"particles\": " << s.particles << ",\n  \"bonds\": " << s.bonds << ",\n"
      << "  \"time_step\": " << jsonString(s.stepControl) << ",\n"
      << "  \"dt\": " << s.dt << ",\n  \"dt_min\": " << s.dtMin << ",\n  \"dt_max\": " << s.dtMax
      << ",\n  \"stable_dt\": " << s.stableDt << ",\n"
      << "  \"substeps_per_frame\": " << (s.substeps > 0 ? std::to_string(s.substeps) : "null")
      << ",\n  \"steps\": " << s.steps << ",\n"
      << "  \"steps_limited_by\": {\"bound\": " << s.limitedBy[0]
      << ", \"stretch\": " << s.limitedBy[1] << ", \"burst\": " << s.limitedBy[2]
      << ", \"growth\": " << s.limitedBy[3] << "},\n"
      << "  \"largest_burst\": " << s.largestBurst << ",\n"
      << "  \"extra_substeps\": " << s.extraSubsteps << ",\n"
      << "  \"contact_list_builds\": " << s.contactListBuilds << ",\n"
      << "  \"frames_simulated\": " << s.framesSimulated << ",\n"
      << "  \"frames_written\": " << s.framesWritten << ",\n"
      << "  \"resumed_after_frame\": " << s.resumedAfter << ",\n"
      << "  \"cache\": {\"frames\": " << s.framesCached << ", \"bytes\": " << s.cacheBytes
      << ", \"bytes_per_particle_frame\": "
      << (s.framesCached > 0 ? double(s.cacheBytes) / s.framesCached / s.particles : 0.0) << "},\n"
      << "  \"vdb\": " << volumeJson(s.volume, scene.sim.sheet.thickness) << ",\n"
      << "  \"threads\": " << omp_get_max_threads() << ",\n"
      << "  \"wall_seconds\": {\"setup\": " << s.seconds.setup
      << ", \"simulate\": " << s.seconds.simulate << ", \"contact\": " << s.seconds.contact
      << ", \"contact_lists\": " << s.seconds.contactLists << ", \"surface\": " << s.seconds.surface
      << ", \"render\": " << s.seconds.render << ", \"write\": " << s.seconds.write
      << ", \"cache\": " << s.seconds.cache << "},\n"
      << "  \"ns_per_particle_step\": " << s.nsPerParticleStep << ",\n"
      << "  \"state_hash\": " << jsonString(hash) << ",\n"
      << "  \"files\": " << jsonStringArray(files, "  ") << ",\n"
      << "  \"shading\": " << shadingJson(scene.render) << ",\n"
      << "  \"resolved_scene\": " << (scene.resolvedJson.empty() ? "{}" : scene.resolvedJson)
      << "\n}\n";
    return j.str();
}

// The files a run writes: each written frame's, the cache's and stats.csv when asked for
// (run.json is the list itself).
std::vector<std::string> plannedFiles(const FrameWriter& writer, std::span<const int> frames,
                                      int last, int cacheEvery, bool withStats) {
    std::vector<std::string> names;
    if (withStats) names.push_back("stats.csv");
    for (const int frame : frames)
        for (std::string& name : writer.plannedFiles(frame)) names.push_back(std::move(name));
    if (cacheEvery > 0) names.push_back(kCacheSourceName);
    for (int frame = cacheEvery; cacheEvery > 0 && frame <= last; frame += cacheEvery)
        names.push_back(cacheFileName(frame));
    return names;
}

// What rend render rebuilds the scene from: its file and the --set values of the run.
void writeCacheSource(const Scene& scene, const std::filesystem::path& outDir) {
    toml::array overrides;
    for (const std::string& set : scene.overrides) overrides.push_back(set);
    const toml::table source{{"scene", std::filesystem::absolute(scene.file).string()},
                             {"overrides", overrides}};
    std::ostringstream text;
    text << "# Written by rend run: rend render rebuilds the scene from this.\n" << source << "\n";
    std::filesystem::create_directories(outDir / "cache");
    render::writeFileAtomic(outDir / kCacheSourceName, text.str());
}

void reportRemoved(const std::vector<std::string>& removed, const std::filesystem::path& dir) {
    if (removed.empty()) return;
    std::string names;
    for (std::size_t k = 0; k < std::min<std::size_t>(removed.size(), 3); ++k)
        names += (k ? ", " : "") + removed[k];
    std::fprintf(stderr,
                 "removed %zu file%s of the previous run in %s that this run does not "
                 "write (%s%s)\n",
                 removed.size(), removed.size() == 1 ? "" : "s", dir.c_str(), names.c_str(),
                 removed.size() > 3 ? ", ..." : "");
}

// The frame's stats row. A value that is not finite stops the run before the row or the frame
// is written, naming the fastest particle (the guard's checks normally stop it earlier).
StatsWriter::Row frameStats(int frame, const sim::Membrane& m) {
    const StatsWriter::Row row{frame,        m.time(),     m.kineticEnergy(),   m.strainEnergy(),
                               m.maxSpeed(), m.maxTheta(), m.brokenBondCount(), m.stepCount(),
                               m.timeStep()};
    const std::pair<const char*, double> values[] = {{"kinetic energy", row.kineticEnergy},
                                                     {"strain energy", row.strainEnergy},
                                                     {"largest speed", row.maxSpeed},
                                                     {"largest theta", row.maxTheta}};
    for (const auto& [name, value] : values) {
        if (std::isfinite(value)) continue;
        const auto& v = m.velocities();
        const int fastest = int(std::max_element(v.begin(), v.end(),
                                                 [](const auto& a, const auto& b) {
                                                     return a.squaredNorm() < b.squaredNorm();
                                                 }) -
                                v.begin());
        const double suggested = sim::suggestedTimeStep(m.timeStep(), m.stableTimeStep());
        std::ostringstream msg;
        msg << "numerical blow-up at step " << m.stepCount() << " (t = " << m.time() << " s): the "
            << name << " of frame " << frame << " is not finite; the fastest particle is particle "
            << fastest << ". Use a smaller dt";
        if (suggested > 0.0) msg << " (dt <= " << suggested << ")";
        msg << " or milder boundary velocities, gravity, pressure or material values.";
        throw sim::NumericalBlowUp(msg.str(), m.stepCount(), fastest, suggested);
    }
    return row;
}

}  // namespace

RunEstimate estimateRun(const Scene& scene, const sim::Membrane& membrane) {
    RunEstimate e;
    e.frames = scene.frameCount();
    e.particles = membrane.particleCount();
    e.bonds = double(membrane.bondCount());
    const double interval = 1.0 / scene.sim.time.fps;
    e.stepsPerFrame = std::max(1.0, std::ceil(interval / membrane.timeStep() * (1.0 - 1e-12)));
    const double steps = e.stepsPerFrame * e.frames;
    const sim::Diffusion* diffusion = membrane.diffusion();
    if (diffusion && std::isfinite(diffusion->stableTimeStep())) {
        const double h = interval / e.stepsPerFrame;
        e.diffusionSubsteps = std::max(1.0, std::ceil(h / (0.9 * diffusion->stableTimeStep())));
    }
    e.particleSteps = steps * e.particles;
    e.bondSteps = steps * 2 * e.bonds;
    const double stepNs = e.particles * kNsPerParticle + 2 * e.bonds * kNsPerBondEnd;
    const double diffusionNs =
        e.diffusionSubsteps * (e.particles * kNsPerDiffusionParticle + 2 * e.bonds * kNsPerBondEnd);
    e.diffusionSeconds = steps * diffusionNs * 1e-9;
    e.seconds = steps * stepNs * 1e-9 + e.diffusionSeconds;
    e.bytes = estimateSheet(scene.sim.sheet).bytes;
    return e;
}

std::string describeEstimate(const RunEstimate& e) {
    std::string text = roundedText(e.stepsPerFrame * e.frames) + " steps (" +
                       roundedText(e.stepsPerFrame) + " per frame x " + std::to_string(e.frames) +
                       " frames)";
    if (e.diffusionSubsteps > 0)
        text += ", " + roundedText(e.diffusionSubsteps) + " diffusion sub-steps per step";
    return text + ", " + roundedText(e.particleSteps) + " particle-steps, " +
           roundedText(e.bondSteps) + " bond-steps: about " + durationText(e.seconds) +
           " on one core";
}

sim::Membrane prepareMembrane(const Scene& scene) {
    sim::Membrane membrane = [&] {
        try {
            sim::MembraneParams params = scene.sim;
            params.particleLevelSet = scene.render.surface == render::SurfaceKind::ParticleLevelSet;
            return sim::Membrane(params);
        } catch (const std::invalid_argument& e) {
            throw SceneError(scene.file.string() + ": error: " + e.what());
        }
    }();
    checkTimeStep(scene, membrane);
    checkBoundaries(scene, membrane);
    checkNotches(scene, membrane);
    checkCost(scene, estimateRun(scene, membrane));
    return membrane;
}

std::pair<int, double> substepsPerFrame(double dt, double fps) {
    const double interval = 1.0 / fps;
    const int substeps = std::max(1, int(std::ceil(interval / dt * (1.0 - 1e-12))));
    return {substeps, interval / substeps};
}

std::uintmax_t cacheFrameBytes(const sim::Membrane& membrane) {
    return membrane.saveState().size();
}

namespace {

/// Loads the last complete cached frame of outDir into `membrane`; returns its frame. Throws
/// SceneError when there is none for this scene.
int resumeFromCache(const Scene& scene, const std::filesystem::path& outDir, int last,
                    sim::Membrane& membrane) {
    const std::uint64_t particles = std::uint64_t(membrane.particleCount());
    std::string newestRefused;
    const std::optional<int> frame = lastCompleteCacheFrame(
        outDir, last, scene.simulationFingerprint, particles, &newestRefused);
    if (!frame)
        throw SceneError("--resume: error: " + outDir.string() +
                         " holds no complete cached frame of this scene (cache/frame_N.rcache "
                         "written by rend run with the same scene and --set values). Run "
                         "without --resume." +
                         (newestRefused.empty() ? "" : " The newest cache file: " + newestRefused));
    const CacheFrame cached =
        readCacheFrameFor(outDir, *frame, scene.simulationFingerprint, particles);
    try {
        membrane.loadState(cached.state);
    } catch (const sim::StateMismatch& e) {
        throw CacheError((outDir / cacheFileName(*frame)).string() + ": error: " + e.what() +
                         ". Rerun without --resume.");
    }
    return *frame;
}

/// The stats rows of frames 1..upTo a killed or finished run left (stats.csv.partial, else
/// stats.csv), as text.
std::string statsRowsUpTo(const std::filesystem::path& outDir, int upTo) {
    std::ifstream in(outDir / "stats.csv.partial");
    if (!in) in.open(outDir / "stats.csv");
    std::string line, rows;
    std::getline(in, line);  // the header
    while (std::getline(in, line)) {
        int frame = 0;
        if (std::sscanf(line.c_str(), "%d,", &frame) == 1 && frame >= 1 && frame <= upTo)
            rows += line + "\n";
    }
    return rows;
}

/// The files of frames 1..upTo that the run being resumed completed.
std::vector<std::string> filesUpTo(const std::filesystem::path& outDir,
                                   const std::vector<std::string>& planned, int upTo) {
    std::vector<std::string> done;
    for (const std::string& name : planned) {
        int frame = 0;
        const std::size_t at = name.find("frame_");
        if (at == std::string::npos || std::sscanf(name.c_str() + at, "frame_%d", &frame) != 1 ||
            frame > upTo || !std::filesystem::exists(outDir / name))
            continue;
        done.push_back(name);
    }
    return done;
}

/// This process's slab when mpirun started several (app/MpiDomain.h), else null.
std::unique_ptr<sim::Domain> decompose(const Scene& scene, sim::Membrane& membrane) {
    if (processCount() <= 1) return nullptr;
    try {
        std::unique_ptr<sim::Domain> domain = makeMpiDomain(membrane.bonds());
        membrane.decompose(*domain);
        return domain;
    } catch (const std::invalid_argument& e) {
        throw SceneError(scene.file.string() + ": error: " + e.what());
    }
}

/// The steps of a process other than the first: its slab's, with the first's gathers, and
/// nothing written.
RunSummary runSlab(const Scene& scene, const RunOptions& options, sim::Membrane& membrane, int last,
                   int substeps) {
    RunSummary s;
    int frame = options.resume ? resumeFromCache(scene, options.outDir, last, membrane) : 0;
    std::optional<ThreadGovernor> governor;
    if (options.followLoad) governor.emplace(usableCores());
    while (++frame <= last) {
        if (governor) governor->atFrame();
        membrane.startFrame();
        if (scene.sim.time.adaptive())
            membrane.advanceTo(frame / scene.sim.time.fps);
        else
            for (int k = 0; k < substeps; ++k) membrane.step();
        membrane.gatherToFirst();
    }
    s.particles = membrane.particleCount();
    s.steps = membrane.stepCount();
    return s;
}

}  // namespace

RunSummary runScene(const Scene& scene, const RunOptions& options) {
    RunSummary s;
    auto t0 = Clock::now();
    sim::Membrane membrane = prepareMembrane(scene);
    const sim::TimeParams& time = scene.sim.time;
    const bool adaptive = time.adaptive();
    // A fixed step is evened out to divide the frame; adaptive steps land on frames themselves.
    const auto [substeps, dt] = substepsPerFrame(membrane.timeStep(), time.fps);
    if (!adaptive) membrane.setTimeStep(dt);
    s.particles = membrane.particleCount();
    s.bonds = membrane.bondCount();
    s.stepControl = time.dt ? "fixed" : adaptive ? "adaptive" : "auto";
    s.dt = s.dtMin = s.dtMax = adaptive ? 0.0 : dt;
    s.stableDt = membrane.stableTimeStep();
    s.substeps = adaptive ? 0 : substeps;
    if (processRank() == 0)
        std::fprintf(stderr, "estimate: %s\n",
                     describeEstimate(estimateRun(scene, membrane)).c_str());
    std::vector<int> selected = options.frames;
    if (selected.empty())
        for (int frame = 1; frame <= scene.frameCount(); ++frame) selected.push_back(frame);
    const int last = selected.back();
    const auto isSelected = [&](int frame) {
        return std::binary_search(selected.begin(), selected.end(), frame);
    };
    const std::unique_ptr<sim::Domain> domain = decompose(scene, membrane);
    if (domain && domain->rank() != 0) return runSlab(scene, options, membrane, last, substeps);

    std::filesystem::create_directories(options.outDir);
    int resumedAfter = 0;
    std::string carriedStats;
    if (options.resume) {
        resumedAfter = resumeFromCache(scene, options.outDir, last, membrane);
        carriedStats = statsRowsUpTo(options.outDir, resumedAfter);
        s.resumedAfter = resumedAfter;
        std::fprintf(stderr, "resuming after frame %d (t = %.6g s, step %ld)\n", resumedAfter,
                     membrane.time(), membrane.stepCount());
    }
    FrameWriter writer(scene, options.outDir);
    const std::vector<std::string> planned =
        plannedFiles(writer, selected, last, options.cacheEvery, scene.writeStats);
    RunFolder folder(options.outDir, planned);
    auto writeRunJson = [&](const std::string& status, const std::vector<std::string>& files) {
        render::writeFileAtomic(options.outDir / "run.json",
                                runJson(scene, s, status, stateHash(membrane), files));
    };
    // Before anything else is written, so a killed run never leaves a folder that looks done.
    writeRunJson("running", folder.listedWhileRunning());
    reportRemoved(folder.removeStale(), options.outDir);
    folder.wrote(filesUpTo(options.outDir, planned, resumedAfter));
    if (options.cacheEvery > 0) {
        writeCacheSource(scene, options.outDir);
        folder.wrote({kCacheSourceName});
    }
    std::optional<StatsWriter> stats;
    if (scene.writeStats) {
        stats.emplace(options.outDir / "stats.csv");
        stats->appendRows(carriedStats);
    }
    Progress progress(options.progressBar, last);
    s.seconds.setup = secondsSince(t0);

    auto finish = [&](const std::string& status) {
        s.steps = membrane.stepCount();
        s.extraSubsteps = membrane.extraSubsteps();
        s.seconds.contact = membrane.contactSeconds();
        if (const sim::Contact* contact = membrane.contact()) {
            s.seconds.contactLists = contact->listBuildSeconds();
            s.contactListBuilds = contact->listBuilds();
        }
        if (adaptive && s.steps > 0) {
            s.dt = membrane.time() / double(s.steps);
            s.dtMin = membrane.smallestTimeStep();
            s.dtMax = membrane.largestTimeStep();
            std::copy_n(membrane.stepController().limitCounts(), s.limitedBy.size(),
                        s.limitedBy.begin());
            s.largestBurst = membrane.stepController().largestBurst();
        }
        if (s.steps > 0)
            s.nsPerParticleStep = s.seconds.simulate * 1e9 / (double(s.steps) * s.particles);
        if (stats && stats->finish()) folder.wrote({"stats.csv"});
        writeRunJson(status, folder.finish());
    };
    // A write failed (a full disk): keep what is complete and mark the run failed, as far as the
    // disk still allows. When even run.json cannot be written it keeps saying "running".
    auto finishAfterFailure = [&] {
        try {
            if (stats && stats->finish()) folder.wrote({"stats.csv"});
        } catch (const std::exception&) {
        }
        const std::vector<std::string> files = folder.finish();
        try {
            writeRunJson("failed", files);
        } catch (const std::exception&) {
        }
    };
    // After the frame's pictures, so a cached frame's files are all complete (--resume). The
    // write goes on while the next frame simulates (app/CacheWriter.h); s.seconds.cache is what
    // the run waited for it, the state's copy included.
    CacheWriter cacheWriter(options.outDir);
    auto cacheFrame = [&](int frame) {
        if (options.cacheEvery <= 0 || frame % options.cacheEvery != 0) return;
        const auto started = Clock::now();
        // The state written into the last frame's storage (Membrane::saveState's `reuse`).
        cacheWriter.start({frame, membrane.time(), scene.simulationFingerprint,
                           std::uint64_t(membrane.particleCount()),
                           membrane.saveState(cacheWriter.takeStorage())});
        s.seconds.cache += secondsSince(started);
    };
    // Before anything of the next frame is written, and before the run ends.
    auto cacheWritten = [&] {
        const auto started = Clock::now();
        if (const auto written = cacheWriter.wait()) {
            s.cacheBytes += written->bytes;
            folder.wrote({cacheFileName(written->frame)});
            ++s.framesCached;
        }
        s.seconds.cache += secondsSince(started);
    };
    std::vector<std::string> frameFiles;  // the current frame's, as they are completed
    std::optional<ThreadGovernor> governor;
    if (options.followLoad) governor.emplace(usableCores());
    try {
        for (int frame = resumedAfter + 1; frame <= last; ++frame) {
            if (governor) governor->atFrame();
            t0 = Clock::now();
            membrane.startFrame();  // a frame's lists are its own: checkpoints resume exactly
            if (adaptive)
                membrane.advanceTo(frame / time.fps);
            else
                for (int k = 0; k < substeps; ++k) membrane.step();
            membrane.gatherToFirst();  // the whole sheet, from every process's slab
            s.seconds.simulate += secondsSince(t0);
            cacheWritten();
            s.framesSimulated = frame;
            const StatsWriter::Row row = frameStats(frame, membrane);  // checks it is finite
            if (stats) stats->append(row);
            frameFiles.clear();
            if (isSelected(frame) && writer.active()) {
                membrane.updateDamage();
                writer.write(membrane.view(frame), s.seconds, frameFiles);
                s.volume = writer.lastVolume();
                folder.wrote(frameFiles);
                ++s.framesWritten;
            }
            cacheFrame(frame);
            progress.frameDone(frame, membrane.time(), frameFiles.empty() ? "" : frameFiles[0]);
        }
        cacheWritten();
        s.framesSimulated = std::max(s.framesSimulated, resumedAfter);
        finish("ok");
    } catch (const sim::NumericalBlowUp& e) {
        try {
            cacheWritten();  // the last frame's write failed first: that is the run's failure
        } catch (...) {
            finishAfterFailure();
            throw;
        }
        finish("blow-up");
        // Located at the time step, the value the advice is about.
        throw sim::NumericalBlowUp(scene.locationOf("time.dt") + ": error: " + e.what(), e.step,
                                   e.particle, e.suggestedDt);
    } catch (...) {
        folder.wrote(frameFiles);
        std::exception_ptr failure = std::current_exception();
        try {
            cacheWritten();
        } catch (...) {
            failure = std::current_exception();  // the earlier failure
        }
        finishAfterFailure();
        std::rethrow_exception(failure);
    }
    return s;
}

std::pair<std::filesystem::path, std::vector<std::string>> cacheSource(
    const std::filesystem::path& outDir) {
    const std::filesystem::path file = outDir / kCacheSourceName;
    if (!std::filesystem::exists(file))
        throw SceneError(outDir.string() +
                         ": error: expected the folder of a rend run with its "
                         "cache, found no " +
                         std::string(kCacheSourceName) + ". Run rend run SCENE --out " +
                         outDir.string() + " first.");
    toml::table source;
    try {
        source = toml::parse_file(file.string());
    } catch (const toml::parse_error& e) {
        throw CacheError(file.string() + ": error: " + std::string(e.description()) +
                         ". Rerun rend run into this folder.");
    }
    const std::optional<std::string> scene = source["scene"].value<std::string>();
    const toml::array* overrides = source["overrides"].as_array();
    if (!scene || !overrides)
        throw CacheError(file.string() +
                         ": error: expected scene and overrides. Rerun rend run "
                         "into this folder.");
    std::vector<std::string> sets;
    for (const toml::node& set : *overrides)
        if (const auto text = set.value<std::string>()) sets.push_back(*text);
    return {*scene, sets};
}

namespace {

/// The frames outDir's cache holds, ascending.
std::vector<int> cachedFrames(const std::filesystem::path& outDir) {
    std::vector<int> frames;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(outDir / "cache", ec)) {
        int frame = 0;
        char extra = 0;
        const std::string name = entry.path().filename().string();
        if (std::sscanf(name.c_str(), "frame_%d.rcach%c", &frame, &extra) == 2 && extra == 'e' &&
            name == std::filesystem::path(cacheFileName(frame)).filename().string())
            frames.push_back(frame);
    }
    std::sort(frames.begin(), frames.end());
    return frames;
}

bool allExist(const std::filesystem::path& outDir, const std::vector<std::string>& names) {
    return std::all_of(names.begin(), names.end(), [&](const std::string& name) {
        return std::filesystem::exists(outDir / name);
    });
}

}  // namespace

RenderSummary renderFromCache(const Scene& scene, const RenderOptions& options) {
    RenderSummary r;
    auto t0 = Clock::now();
    sim::Membrane membrane = prepareMembrane(scene);
    FrameWriter writer(scene, options.outDir);
    if (!writer.active())
        throw SceneError(
            "rend render: error: nothing to write: the renderer is none and no "
            "export is asked for. Use e.g. --renderer osmesa or --export ply.");
    const std::vector<int> frames =
        options.frames.empty() ? cachedFrames(options.outDir) : options.frames;
    if (frames.empty())
        throw SceneError(options.outDir.string() + ": error: expected cached frames in " +
                         (options.outDir / "cache").string() +
                         ", found none. Run rend run with --cache-every 1 first.");
    const std::uint64_t particles = std::uint64_t(membrane.particleCount());
    Progress progress(options.progressBar, frames.back());
    r.seconds.setup = secondsSince(t0);
    std::vector<std::string> files;
    for (const int frame : frames) {
        if (options.skipExisting && allExist(options.outDir, writer.plannedFiles(frame))) {
            ++r.framesSkipped;
            continue;
        }
        t0 = Clock::now();
        const CacheFrame cached =
            readCacheFrameFor(options.outDir, frame, scene.simulationFingerprint, particles);
        try {
            membrane.loadState(cached.state);
        } catch (const sim::StateMismatch& e) {
            throw CacheError((options.outDir / cacheFileName(frame)).string() +
                             ": error: " + e.what() + ". Rerun rend run into this folder.");
        }
        membrane.updateDamage();
        r.seconds.simulate += secondsSince(t0);
        files.clear();
        writer.write(membrane.view(frame), r.seconds, files);
        ++r.framesWritten;
        progress.frameDone(frame, membrane.time(), files.empty() ? "" : files[0]);
    }
    return r;
}

}  // namespace rend
