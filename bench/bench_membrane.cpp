// Cost of the membrane core on the paper's stretch scene (Fig. 3, ~11.6K particles): ns per
// particle-step at 1 and N threads, and the speed-up against 1 thread in the same run. The
// particle level set's share (seed 004, carried in every step) is BM_LevelSetAdvance, in the
// same units: its ghosts' advance and, every 20th step, its reinitialisation.

#include <benchmark/benchmark.h>
#include <omp.h>

#include "app/Scene.h"
#include "sim/Membrane.h"

namespace {

rend::sim::MembraneParams stretchScene() {
    return rend::loadScene(std::string(REND_SOURCE_DIR) + "/scenes/stretch.toml").sim;
}

void BM_MembraneStep(benchmark::State& state) {
    omp_set_num_threads(int(state.range(0)));
    rend::sim::Membrane membrane(stretchScene());
    for (int s = 0; s < 200; ++s) membrane.step();  // leave the rest state: bonds are stretched
    for (auto _ : state) membrane.step();
    const double particleSteps = double(state.iterations()) * membrane.particleCount();
    state.counters["ns_per_particle_step"] = benchmark::Counter(
        particleSteps * 1e-9, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    state.counters["particles"] = membrane.particleCount();
}

void BM_LevelSetAdvance(benchmark::State& state) {
    omp_set_num_threads(1);
    rend::sim::Membrane membrane(stretchScene());  // without a level set of its own
    for (int s = 0; s < 200; ++s) membrane.step();
    const rend::sim::FrameView v = membrane.view(0);
    rend::sim::ParticleLevelSet levelSet(membrane.params().sheet, v.restPositions, v.restTriangles,
                                         v.bondOffsets, v.bondPartners);
    levelSet.start(v.positions, v.bondAlive);
    long step = 0;
    for (auto _ : state) levelSet.advance(v.positions, v.velocities, v.bondAlive, 0, 1e-4, ++step);
    const double particleSteps = double(state.iterations()) * membrane.particleCount();
    state.counters["ns_per_particle_step"] = benchmark::Counter(
        particleSteps * 1e-9, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    state.counters["ghosts"] = double(levelSet.ghostPositions().size());
}

}  // namespace

BENCHMARK(BM_LevelSetAdvance)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_MembraneStep)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();
