// Seconds per 20 time steps of every shipped scene, the figure of the membrane paper's Table 1
// (0.2, 0.2, 0.6, 0.2, 0.2 s on a 1.8 GHz laptop i7 for stretch/shear, crack path, foil, rubbery
// film, seaweed). Each scene first runs 1 s of simulated time (or 2000 steps), so the measured
// steps include its cracks, sources and sub-stepped diffusion.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>

#include "app/Pipeline.h"
#include "app/Scene.h"

namespace {

void BM_Scene(benchmark::State& state, const std::filesystem::path& file) {
    const rend::Scene scene = rend::loadScene(file);
    rend::sim::Membrane membrane = rend::prepareMembrane(scene);
    const int warmUp = std::min(2000, int(1.0 / membrane.timeStep()));
    for (int s = 0; s < warmUp; ++s) membrane.step();
    for (auto _ : state)
        for (int s = 0; s < 20; ++s) membrane.step();
    state.counters["particles"] = membrane.particleCount();
    state.counters["broken_bonds"] = double(membrane.brokenBondCount());
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<std::filesystem::path> scenes;
    for (const auto& e : std::filesystem::directory_iterator(REND_SOURCE_DIR "/scenes"))
        if (e.path().extension() == ".toml") scenes.push_back(e.path());
    std::sort(scenes.begin(), scenes.end());
    for (const auto& file : scenes)
        benchmark::RegisterBenchmark(("ms_per_20_steps/" + file.stem().string()).c_str(), BM_Scene,
                                     file)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
}
