// Rays per second of the Embree path tracer on a ~10K-triangle aluminium-foil sheet at
// 320 x 180, 16 spp, with 1 and 2 OpenMP threads; the OSMesa preview's frame time on the same
// mesh and size for reference. Prints figures, asserts nothing.

#include <benchmark/benchmark.h>
#include <omp.h>

#include <cmath>
#include <numbers>

#include "render/EmbreeRenderer.h"
#include "render/OsmesaRenderer.h"

namespace {

using rend::render::Mesh;
using rend::render::RenderSettings;

// 71 x 71 vertices: 70 * 70 * 2 = 9800 triangles over 2 x 2 m, crumpled by two waves.
Mesh crumpledSheet() {
    constexpr int n = 71;
    constexpr double size = 2.0;
    const double tau = 2.0 * std::numbers::pi;
    auto height = [&](double x, double y) {
        return 0.12 * std::sin(tau * x / 1.1) * std::cos(tau * y / 1.7) +
               0.02 * std::sin(tau * (0.7 * x + y) / 0.3);
    };
    Mesh mesh;
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
            const double x = (double(i) / (n - 1) - 0.5) * size;
            const double y = (double(j) / (n - 1) - 0.5) * size;
            const double h = 1e-4;
            const double gx = (height(x + h, y) - height(x - h, y)) / (2 * h);
            const double gy = (height(x, y + h) - height(x, y - h)) / (2 * h);
            mesh.positions.emplace_back(float(x), float(y), float(height(x, y)));
            mesh.normals.push_back(Eigen::Vector3d(-gx, -gy, 1.0).normalized().cast<float>());
            mesh.colors.emplace_back(0.8f, 0.8f, 0.8f);
        }
    }
    for (int j = 0; j + 1 < n; ++j) {
        for (int i = 0; i + 1 < n; ++i) {
            const auto a = std::uint32_t(j * n + i);
            mesh.triangles.push_back({a, a + 1, a + n + 1});
            mesh.triangles.push_back({a, a + n + 1, a + n});
        }
    }
    return mesh;
}

RenderSettings benchSettings() {
    RenderSettings settings;
    settings.width = 320;
    settings.height = 180;
    settings.camera.position = Eigen::Vector3d(0.6, -3.0, 1.4);
    settings.camera.lookAt = Eigen::Vector3d(0.0, 0.0, -0.1);
    settings.pathTracing.samplesPerPixel = 16;
    settings.pathTracing.maxDepth = 4;
    settings.pathTracing.material = rend::render::MaterialKind::Conductor;
    return settings;
}

void BM_PathTracer(benchmark::State& state) {
    const int previous = omp_get_max_threads();
    omp_set_num_threads(int(state.range(0)));
    const Mesh mesh = crumpledSheet();
    const RenderSettings settings = benchSettings();
    rend::render::EmbreeRenderer renderer;
    renderer.render(mesh, settings);  // the first frame builds the BVH; later ones refit
    long long rays = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(renderer.render(mesh, settings));
        rays += renderer.raysTraced();
    }
    omp_set_num_threads(previous);
    state.counters["rays_per_second"] =
        benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
    state.counters["rays_per_frame"] = double(renderer.raysTraced());
    state.counters["triangles"] = double(mesh.triangles.size());
    state.SetLabel(renderer.deviceDescription());
}

void BM_Osmesa(benchmark::State& state) {
    const Mesh mesh = crumpledSheet();
    const RenderSettings settings = benchSettings();  // supersample 2: 640 x 360 rasterized
    rend::render::OsmesaRenderer renderer;
    for (auto _ : state) benchmark::DoNotOptimize(renderer.render(mesh, settings));
    state.SetLabel(renderer.glDescription());
}

}  // namespace

BENCHMARK(BM_PathTracer)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Osmesa)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
