// Noise against time of the Embree path tracer, for scripts/bench_cycles.sh (which compares it
// with Blender Cycles at equal RMSE). Two commands:
//
//   bench_noise render SCENE FRAME WIDTH HEIGHT OUT_DIR SPP... ref=SPP
//       simulates SCENE to FRAME once, exports its lattice mesh (OUT_DIR/meshes/frame_N.ply and
//       a run.json for scripts/blender_import.py), then renders it at each SPP into
//       OUT_DIR/rend_SPP.exr and prints "rend spp=S seconds=T" (the best of a few renders when
//       they are short); ref=SPP renders the reference with another seed; dn=SPP renders with
//       the denoiser on into OUT_DIR/rend_dnSPP.exr. T counts everything from
//       handing the mesh to a new renderer (device, BVH build) to the linear image; not the
//       simulation, the PNG or the EXR.
//   bench_noise rmse REFERENCE.exr IMAGE.exr...
//       prints "rmse IMAGE VALUE": the root-mean-square difference of R, G and B against the
//       reference, each value clamped to [0, 1] first (the display range: noise in a highlight
//       that clips to white is not seen), and the unclamped figure after it.

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <string>
#include <vector>

#include "app/Outputs.h"
#include "app/Pipeline.h"
#include "render/EmbreeRenderer.h"
#include "render/ExrWriter.h"
#include "render/LatticeSurface.h"
#include "render/MeshExport.h"

namespace {

using Clock = std::chrono::steady_clock;

int usage() {
    std::fprintf(stderr,
                 "usage: bench_noise render SCENE FRAME WIDTH HEIGHT OUT_DIR SPP...\n"
                 "       bench_noise rmse REFERENCE.exr IMAGE.exr...\n");
    return 2;
}

rend::render::Mesh frameMesh(const rend::Scene& scene, int frame) {
    rend::sim::Membrane membrane = rend::prepareMembrane(scene);
    const auto [substeps, dt] = rend::substepsPerFrame(membrane.timeStep(), scene.sim.time.fps);
    membrane.setTimeStep(dt);
    for (int k = 0; k < substeps * frame; ++k) membrane.step();
    membrane.updateDamage();
    const rend::sim::FrameView view = membrane.view(frame);
    rend::render::LatticeSurface surface(view);
    return surface.build(view, scene.render);
}

double processSeconds() {
    timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

struct Timing {
    double wall = 0.0;
    double cpu = 0.0;  ///< all threads' CPU seconds: robust on a machine shared with builds
};

/// One render at `spp` by a fresh renderer: its times, and its image and layers.
Timing timeRender(const rend::render::Mesh& mesh, rend::render::RenderSettings settings, int spp,
                  rend::render::Image& image, rend::render::FrameLayers& layers) {
    settings.pathTracing.samplesPerPixel = spp;
    const auto t0 = Clock::now();
    const double c0 = processSeconds();
    rend::render::EmbreeRenderer renderer;
    image = renderer.render(mesh, settings, &layers);
    return {std::chrono::duration<double>(Clock::now() - t0).count(), processSeconds() - c0};
}

int renderCommand(int argc, char** argv) {
    if (argc < 8) return usage();
    const int frame = std::atoi(argv[3]);
    const std::string width = argv[4], height = argv[5];
    const std::filesystem::path out = argv[6];
    const rend::Scene scene =
        rend::loadScene(argv[2], {"render.width=" + width, "render.height=" + height});
    const rend::render::Mesh mesh = frameMesh(scene, frame);
    std::filesystem::create_directories(out / "meshes");
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04d.ply", frame);
    rend::render::exportMesh(mesh, out / "meshes" / name, rend::render::MeshFormat::Ply);
    std::ofstream(out / "run.json") << "{\"shading\": " << rend::shadingJson(scene.render)
                                    << ", \"resolved_scene\": " << scene.resolvedJson << "}\n";
    std::printf("rend threads=%d triangles=%zu\n", omp_get_max_threads(), mesh.triangles.size());
    for (int k = 7; k < argc; ++k) {
        // "ref=N": the reference, with another seed, so that its noise is independent of the
        // measured images' (the same seed would share their first samples).
        const bool reference = std::string(argv[k]).rfind("ref=", 0) == 0;
        const bool denoised = std::string(argv[k]).rfind("dn=", 0) == 0;
        const int spp = std::atoi(argv[k] + (reference ? 4 : denoised ? 3 : 0));
        rend::render::RenderSettings settings = scene.render;
        settings.pathTracing.seed = reference ? 1 : 0;
        settings.pathTracing.denoise = denoised;
        rend::render::FrameLayers layers;
        rend::render::Image image;
        Timing best = timeRender(mesh, settings, spp, image, layers);
        // Short renders are repeated: on a shared machine the minimum is the honest figure.
        for (int repeat = 1; repeat < 3 && best.wall < 2.0; ++repeat) {
            const Timing t = timeRender(mesh, settings, spp, image, layers);
            best = {std::min(best.wall, t.wall), std::min(best.cpu, t.cpu)};
        }
        const std::string stem = (denoised ? "rend_dn" : "rend_") + std::to_string(spp);
        rend::render::writeExrAtomic(layers, out / (stem + ".exr"));
        rend::render::writePngAtomic(image, out / (stem + ".png"));
        std::printf("rend%s spp=%d seconds=%.4f cpu=%.4f\n", denoised ? "_denoised" : "", spp,
                    best.wall, best.cpu);
        std::fflush(stdout);
    }
    return 0;
}

/// IMAGE.err.png: each pixel's error (clamped, max over R, G, B) x 8, to see where noise is.
void writeErrorPng(const rend::render::ExrChannels& reference,
                   const rend::render::ExrChannels& image, const std::string& path) {
    rend::render::Image error{
        image.width, image.height,
        std::vector<std::uint8_t>(std::size_t(image.width) * image.height * 3)};
    for (std::size_t i = 0; i < error.rgb.size() / 3; ++i) {
        double e = 0.0;
        for (const char* c : {"R", "G", "B"})
            e = std::max(e, std::abs(std::clamp(double(image.channels.at(c)[i]), 0.0, 1.0) -
                                     std::clamp(double(reference.channels.at(c)[i]), 0.0, 1.0)));
        const auto v = std::uint8_t(std::min(255.0, 8.0 * 255.0 * e));
        error.rgb[3 * i] = error.rgb[3 * i + 1] = error.rgb[3 * i + 2] = v;
    }
    rend::render::writePngAtomic(error, path + ".err.png");
}

int rmseCommand(int argc, char** argv) {
    if (argc < 4) return usage();
    const rend::render::ExrChannels reference = rend::render::readExr(argv[2]);
    for (int k = 3; k < argc; ++k) {
        const rend::render::ExrChannels image = rend::render::readExr(argv[k]);
        if (image.width != reference.width || image.height != reference.height) {
            std::fprintf(stderr, "bench_noise: %s differs in size from the reference\n", argv[k]);
            return 1;
        }
        double clamped = 0.0, raw = 0.0;
        std::size_t count = 0;
        for (const char* c : {"R", "G", "B"}) {
            const std::vector<float>& a = reference.channels.at(c);
            const std::vector<float>& b = image.channels.at(c);
            for (std::size_t i = 0; i < a.size(); ++i) {
                const double d = double(b[i]) - a[i];
                const double dc =
                    std::clamp(double(b[i]), 0.0, 1.0) - std::clamp(double(a[i]), 0.0, 1.0);
                raw += d * d;
                clamped += dc * dc;
                ++count;
            }
        }
        std::printf("rmse %s %.6g %.6g\n", argv[k], std::sqrt(clamped / count),
                    std::sqrt(raw / count));
        if (std::getenv("BENCH_NOISE_ERROR_PNG")) writeErrorPng(reference, image, argv[k]);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        if (argc >= 2 && std::string(argv[1]) == "render") return renderCommand(argc, argv);
        if (argc >= 2 && std::string(argv[1]) == "rmse") return rmseCommand(argc, argv);
        return usage();
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_noise: %s\n", e.what());
        return 1;
    }
}
