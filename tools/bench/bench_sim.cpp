// Benchmarks of the simulation stage: one frame of the cloud showcase (all
// fields applied, adaptive substeps) and the density splat.

#include <vfield/scene/scene.h>
#include <vfield/sim/simulator.h>
#include <vfield/volume/density_splat.h>

#include <benchmark/benchmark.h>

#include <tbb/global_control.h>

#include <map>
#include <memory>

using namespace vfield;

namespace {

struct CloudAtFrame100 {
    std::unique_ptr<Simulator> simulator;
    std::string state; ///< the state at frame 100, to reset to
};

/// The cloud showcase with `particles` particles, advanced to frame 100 (the
/// cloud over the valley, near the terrain), built once per count.
CloudAtFrame100& cloudAtFrame100(int64_t particles)
{
    static std::map<int64_t, CloudAtFrame100> cache;
    CloudAtFrame100& cloud = cache[particles];
    if (!cloud.simulator) {
        Scene scene = loadScene(VFIELD_SCENES_DIR "/cloud_over_terrain.json");
        scene.simulation.clouds[0].count = particles;
        cloud.simulator = std::make_unique<Simulator>(scene.simulation);
        while (cloud.simulator->frame() < 100) cloud.simulator->advanceFrame();
        cloud.state = cloud.simulator->serializeState();
    }
    return cloud;
}

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
BENCHMARK(BM_CloudFrame)->Args({50'000, 1})->Args({50'000, 2})->Args({1'000'000, 1})->Args({1'000'000, 2})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_DensitySplat(benchmark::State& state)
{
    CloudAtFrame100& cloud = cloudAtFrame100(state.range(0));
    cloud.simulator->restoreState(cloud.state);
    const Simulator& simulator = *cloud.simulator;
    const Scene scene = loadScene(VFIELD_SCENES_DIR "/cloud_over_terrain.json");
    for (auto _ : state) benchmark::DoNotOptimize(splatParticles(simulator.particles(), scene.volume));
    state.SetItemsProcessed(state.iterations() * int64_t(simulator.particles().size()));
}
BENCHMARK(BM_DensitySplat)->Arg(50'000)->Arg(1'000'000)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace
