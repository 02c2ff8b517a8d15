// Benchmarks of the simulation stage: one frame of the cloud showcase (all
// fields applied, adaptive substeps) and the density splat.

#include "bench_showcase.h"

#include <vfield/volume/density_splat.h>

#include <benchmark/benchmark.h>

#include <tbb/global_control.h>

using namespace vfield;
using namespace vfield::bench;

namespace {

void BM_CloudFrame(benchmark::State& state)
{
    const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(1)));
    CloudAtFrame100& cloud = cloudAtFrame100(state.range(0));
    uint64_t substeps = 0;
    for (auto _ : state) {
        state.PauseTiming();
        cloud.simulator->restoreState(cloud.state); // every iteration steps the same frame
        state.ResumeTiming();
        cloud.simulator->advanceFrame();
        substeps += cloud.simulator->lastStep().substeps;
    }
    state.counters["particle_steps_per_s"] = benchmark::Counter(double(substeps), benchmark::Counter::kIsRate);
    state.counters["particles"] = double(cloud.simulator->particles().size());
}
BENCHMARK(BM_CloudFrame)
    ->ArgNames({"particles", "threads"})
    ->Args({50'000, 1})
    ->Args({50'000, 2})
    ->Args({125'000, 2})
    ->Args({250'000, 2})
    ->Args({500'000, 2})
    ->Args({1'000'000, 1})
    ->Args({1'000'000, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_DensitySplat(benchmark::State& state)
{
    CloudAtFrame100& cloud = cloudAtFrame100(state.range(0));
    cloud.simulator->restoreState(cloud.state);
    const Simulator& simulator = *cloud.simulator;
    const Scene scene = loadScene(VFIELD_SCENES_DIR "/cloud_over_terrain.json");
    for (auto _ : state) benchmark::DoNotOptimize(splatParticles(simulator.particles(), scene.volume));
    state.SetItemsProcessed(state.iterations() * int64_t(simulator.particles().size()));
}
BENCHMARK(BM_DensitySplat)
    ->ArgName("particles")
    ->Arg(50'000)
    ->Arg(125'000)
    ->Arg(250'000)
    ->Arg(500'000)
    ->Arg(1'000'000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

} // namespace
