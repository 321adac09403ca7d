#include "app/Pipeline.h"

#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>

#include "app/FrameWriter.h"
#include "app/Outputs.h"
#include "app/SceneError.h"

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
    msg << scene.dtLocation << ": error: time.dt: expected at most the stable limit "
        << membrane.stableTimeStep() << " s for E=" << m.youngsModulus << " Pa, rho=" << m.density
        << " kg/m^3, dx=" << scene.sim.sheet.dx << " m (Silling-Askari bound), found " << *t.dt
        << ". Use dt <= " << t.safety * membrane.stableTimeStep() << " or dt = \"auto\".";
    throw SceneError(msg.str());
}

void checkBoundaries(const Scene& scene, const sim::Membrane& membrane) {
    const std::vector<int> counts = membrane.boundaryParticleCounts();
    for (std::size_t k = 0; k < counts.size(); ++k)
        if (counts[k] == 0)
            throw SceneError(scene.file.string() + ": error: boundary " + std::to_string(k) +
                             ": expected a region that holds particles, found none inside it. "
                             "Widen its depth or box, or check it against the sheet's size.");
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

std::string runJson(const Scene& scene, const RunSummary& s, const std::string& status,
                    const std::string& hash) {
    std::ostringstream j;
    j.precision(10);
    j << "{\n  \"rend_version\": " << jsonString(REND_VERSION) << ",\n"
      << "  \"scene\": " << jsonString(scene.file.string()) << ",\n"
      << "  \"status\": " << jsonString(status) << ",\n"
      << "  \"particles\": " << s.particles << ",\n  \"bonds\": " << s.bonds << ",\n"
      << "  \"dt\": " << s.dt << ",\n  \"stable_dt\": " << s.stableDt << ",\n"
      << "  \"substeps_per_frame\": " << s.substeps << ",\n  \"steps\": " << s.steps << ",\n"
      << "  \"extra_substeps\": " << s.extraSubsteps << ",\n"
      << "  \"frames_simulated\": " << s.framesSimulated << ",\n"
      << "  \"frames_written\": " << s.framesWritten << ",\n"
      << "  \"threads\": " << omp_get_max_threads() << ",\n"
      << "  \"wall_seconds\": {\"setup\": " << s.seconds.setup
      << ", \"simulate\": " << s.seconds.simulate << ", \"surface\": " << s.seconds.surface
      << ", \"render\": " << s.seconds.render << ", \"write\": " << s.seconds.write << "},\n"
      << "  \"ns_per_particle_step\": " << s.nsPerParticleStep << ",\n"
      << "  \"state_hash\": " << jsonString(hash) << ",\n"
      << "  \"resolved_scene\": " << (scene.resolvedJson.empty() ? "{}" : scene.resolvedJson)
      << "\n}\n";
    return j.str();
}

}  // namespace

sim::Membrane prepareMembrane(const Scene& scene) {
    sim::Membrane membrane = [&] {
        try {
            return sim::Membrane(scene.sim);
        } catch (const std::invalid_argument& e) {
            throw SceneError(scene.file.string() + ": error: " + e.what());
        }
    }();
    checkTimeStep(scene, membrane);
    checkBoundaries(scene, membrane);
    return membrane;
}

std::pair<int, double> substepsPerFrame(double dt, double fps) {
    const double interval = 1.0 / fps;
    const int substeps = std::max(1, int(std::ceil(interval / dt * (1.0 - 1e-12))));
    return {substeps, interval / substeps};
}

std::pair<int, int> parseFrameRange(const std::string& text, int frameCount) {
    int first = 0, last = 0;
    char extra = 0;
    const bool single = std::sscanf(text.c_str(), "%d%c", &first, &extra) == 1;
    const bool range = std::sscanf(text.c_str(), "%d-%d%c", &first, &last, &extra) == 2;
    if (single) last = first;
    if ((!single && !range) || first < 1 || last < first || last > frameCount)
        throw SceneError("--frames " + text + ": error: expected N or FIRST-LAST within 1-" +
                         std::to_string(frameCount) + " (the scene has " +
                         std::to_string(frameCount) + " frames). Use e.g. --frames 1-" +
                         std::to_string(frameCount) + ".");
    return {first, last};
}

RunSummary runScene(const Scene& scene, const RunOptions& options) {
    RunSummary s;
    auto t0 = Clock::now();
    sim::Membrane membrane = prepareMembrane(scene);
    const auto [substeps, dt] = substepsPerFrame(membrane.timeStep(), scene.sim.time.fps);
    membrane.setTimeStep(dt);
    s.particles = membrane.particleCount();
    s.bonds = membrane.bondCount();
    s.dt = dt;
    s.stableDt = membrane.stableTimeStep();
    s.substeps = substeps;
    const int frames = scene.frameCount();
    const auto [first, last] = options.frames.value_or(std::pair{1, frames});

    std::filesystem::create_directories(options.outDir);
    StatsWriter stats(options.outDir / "stats.csv");
    FrameWriter writer(scene, options.outDir);
    Progress progress(options.progressBar, last);
    s.seconds.setup = secondsSince(t0);

    auto finish = [&](const std::string& status) {
        s.steps = membrane.stepCount();
        s.extraSubsteps = membrane.extraSubsteps();
        if (s.steps > 0)
            s.nsPerParticleStep = s.seconds.simulate * 1e9 / (double(s.steps) * s.particles);
        stats.finish();
        writeFileAtomic(options.outDir / "run.json",
                        runJson(scene, s, status, stateHash(membrane)));
    };
    try {
        for (int frame = 1; frame <= last; ++frame) {
            t0 = Clock::now();
            for (int k = 0; k < substeps; ++k) membrane.step();
            s.seconds.simulate += secondsSince(t0);
            s.framesSimulated = frame;
            stats.append({frame, membrane.time(), membrane.kineticEnergy(), membrane.strainEnergy(),
                          membrane.maxSpeed(), membrane.maxTheta(), membrane.brokenBondCount()});
            std::vector<std::string> wrote;
            if (frame >= first && writer.active()) {
                membrane.updateDamage();
                wrote = writer.write(membrane.view(frame), s.seconds);
                ++s.framesWritten;
            }
            progress.frameDone(frame, membrane.time(), wrote.empty() ? "" : wrote.front());
        }
    } catch (const sim::NumericalBlowUp&) {
        finish("blow-up");
        throw;
    }
    finish("ok");
    return s;
}

}  // namespace rend
