// Seconds per 20 time steps of every shipped scene, the figure of the membrane paper's Table 1
// (0.2, 0.2, 0.6, 0.2, 0.2 s on a 1.8 GHz laptop i7 for stretch/shear, crack path, foil, rubbery
// film, seaweed). Each scene first runs 1 s of simulated time (or 2000 steps), so the measured
// steps include its cracks, sources and sub-stepped diffusion.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "app/Pipeline.h"
#include "app/Scene.h"

namespace {

/// The fixed dt a scene's [time] comment names ("--set time.dt=1e-4"): Table 1's measure is per
/// step at Table 1's step, not the adaptive default's. None: the scene's own step.
std::vector<std::string> table1Step(const std::filesystem::path& file) {
    std::ifstream in(file);
    const std::string text((std::istreambuf_iterator<char>(in)), {});
    const std::string marker = "--set time.dt=";
    const std::size_t at = text.find(marker);
    if (at == std::string::npos) return {};
    const std::size_t end = text.find_first_of(" \n", at + marker.size());
    return {"time.dt=" + text.substr(at + marker.size(), end - at - marker.size())};
}

void BM_Scene(benchmark::State& state, const std::filesystem::path& file) {
    const rend::Scene scene = rend::loadScene(file, table1Step(file));
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
