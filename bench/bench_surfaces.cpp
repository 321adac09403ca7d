// Cost of turning one frame into a surface: ms per frame for the lattice, splat and vdb
// surfaces on wavy hexagonal sheets of ~11.6K (2 x 2 m) and ~104K (6 x 6 m) particles at
// dx = 0.02, the lattice surface on a torn foil (scenes/foil_tear.toml at frame 150, simulated
// once at start-up, ~30 s), and ms to export the 11.6K lattice mesh as binary PLY and GLB.
// Prints only.

#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <numbers>

#include "app/Pipeline.h"
#include "app/Scene.h"
#include "render/LatticeSurface.h"
#include "render/MeshExport.h"
#include "render/SplatSurface.h"
#include "render/VdbSurface.h"
#include "sim/Membrane.h"

namespace {

namespace fs = std::filesystem;
using rend::render::RenderSettings;

// One membrane per sheet size, kept for the whole run: building the bond families of the
// 104K sheet costs more than the surfaces being measured.
const rend::sim::Membrane& wavySheet(double size) {
    static std::map<double, std::unique_ptr<rend::sim::Membrane>> sheets;
    auto& sheet = sheets[size];
    if (!sheet) {
        rend::sim::MembraneParams params;
        params.sheet.size = {size, size};
        params.sheet.dx = 0.02;
        sheet = std::make_unique<rend::sim::Membrane>(params);
        // Not flat, so normals and the level set do real work: a 0.5 m wave 5 cm high.
        for (auto& x : sheet->positions())
            x.z() = 0.05 * std::sin(2.0 * std::numbers::pi * x.x() / 0.5);
    }
    return *sheet;
}

// scenes/foil_tear.toml at t = 12.5 s (frame 150 at 12 fps): torn through, flaps apart. Built
// in place: a Membrane's solvers point into it, so it is never moved.
const rend::sim::Membrane& tornFoil() {
    const fs::path scenes = fs::path(REND_DEFAULT_ASSETS_DIR).parent_path() / "scenes";
    static rend::sim::Membrane foil =
        rend::prepareMembrane(rend::loadScene(scenes / "foil_tear.toml"));
    static const bool simulated = [] {
        while (foil.time() < 12.5) foil.step();
        return true;
    }();
    (void)simulated;
    return foil;
}

double sheetSize(const benchmark::State& state) { return double(state.range(0)); }

void setCounters(benchmark::State& state, const rend::sim::Membrane& sheet, double triangles) {
    state.counters["particles"] = sheet.particleCount();
    state.counters["triangles"] = triangles;
}

void BM_LatticeSurface(benchmark::State& state) {
    const auto& sheet = wavySheet(sheetSize(state));
    const auto frame = sheet.view(1);
    const rend::render::LatticeSurface surface(frame);
    double triangles = 0;
    for (auto _ : state) {
        const auto mesh = surface.build(frame, RenderSettings{});
        triangles = double(mesh.triangles.size());
        benchmark::DoNotOptimize(mesh.positions.data());
    }
    setCounters(state, sheet, triangles);
}

void BM_LatticeSurfaceTornFoil(benchmark::State& state) {
    const auto& foil = tornFoil();
    const auto frame = foil.view(150);
    const rend::render::LatticeSurface surface(frame);
    double triangles = 0;
    for (auto _ : state) {
        const auto mesh = surface.build(frame, RenderSettings{});
        triangles = double(mesh.triangles.size());
        benchmark::DoNotOptimize(mesh.positions.data());
    }
    setCounters(state, foil, triangles);
    state.counters["broken_bonds"] = double(foil.brokenBondCount());
}

void BM_SplatSurface(benchmark::State& state) {
    const auto& sheet = wavySheet(sheetSize(state));
    const auto frame = sheet.view(1);
    const rend::render::SplatSurface surface(frame);
    for (auto _ : state) {
        const auto splats = surface.build(frame, RenderSettings{});
        benchmark::DoNotOptimize(splats.normals.data());
    }
    setCounters(state, sheet, 0);
}

void BM_VdbSurface(benchmark::State& state) {
    const auto& sheet = wavySheet(sheetSize(state));
    const auto frame = sheet.view(1);
    rend::render::VdbSurface surface(frame, rend::render::VdbSettings{});
    double triangles = 0;
    for (auto _ : state) {
        const auto mesh = surface.build(frame, RenderSettings{});
        triangles = double(mesh.triangles.size());
        benchmark::DoNotOptimize(mesh.positions.data());
    }
    setCounters(state, sheet, triangles);
    state.counters["dropped"] = surface.droppedParticles();
}

void BM_ExportLattice(benchmark::State& state) {
    const auto format = rend::render::MeshFormat(state.range(0));
    const auto& sheet = wavySheet(2.0);
    const auto mesh = rend::render::LatticeSurface(sheet.view(1)).build(sheet.view(1), {});
    const fs::path dir = fs::temp_directory_path() / "rend_bench_surfaces";
    fs::create_directories(dir);
    const fs::path path =
        dir / ("lattice" + std::string(rend::render::meshFormatExtension(format)));
    for (auto _ : state) rend::render::exportMesh(mesh, path, format);
    state.counters["bytes"] = double(fs::file_size(path));
    state.SetLabel(std::string(rend::render::meshFormatExtension(format)));
    fs::remove_all(dir);
}

}  // namespace

BENCHMARK(BM_LatticeSurface)->Arg(2)->Arg(6)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_LatticeSurfaceTornFoil)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SplatSurface)->Arg(2)->Arg(6)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_VdbSurface)->Arg(2)->Arg(6)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ExportLattice)
    ->Arg(int(rend::render::MeshFormat::Ply))
    ->Arg(int(rend::render::MeshFormat::Glb))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_MAIN();
