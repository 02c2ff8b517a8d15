// Benchmarks of the Embree back-end on the cloud showcase at frame 100: a
// surface-only frame, and a cloud frame with and without empty-space
// skipping, and with multiple scattering by paths; and the main job's frame
// 120 with more and more particles.

#include "bench_showcase.h"

#include <vfield/volume/density_splat.h>

#include <benchmark/benchmark.h>

#include <limits>

using namespace vfield;
using namespace vfield::bench;

namespace {

void BM_RenderSurfaces(benchmark::State& state)
{
    ShowcaseFrame& s = showcase();
    const RenderSettings settings = s.settings(int(state.range(0)), int(state.range(1)), int(state.range(2)));
    const FrameToRender frame = s.frame(settings, nullptr);
    for (auto _ : state) benchmark::DoNotOptimize(renderFrame(frame));
    state.counters["primary_rays_per_s"] = benchmark::Counter(double(state.range(0) * state.range(1) * state.range(2)),
                                                              benchmark::Counter::kIsIterationInvariantRate);
}
// Pixels doubled three times from 320x180, and the showcase's sizes at one
// sample a pixel and at its own count.
BENCHMARK(BM_RenderSurfaces)
    ->ArgNames({"w", "h", "spp"})
    ->Args({320, 180, 1})
    ->Args({452, 254, 1})
    ->Args({640, 360, 1})
    ->Args({905, 509, 1})
    ->Args({640, 360, kShowcaseSamplesPerPixel})
    ->Args({1280, 720, 1})
    ->Args({1280, 720, kShowcaseSamplesPerPixel})
    ->Args({1920, 1080, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// A whole cloud frame: the volume's light grids are built every iteration, as per frame.
void BM_RenderCloud(benchmark::State& state)
{
    ShowcaseFrame& s = showcase();
    RenderSettings settings = s.settings(int(state.range(0)), int(state.range(1)), int(state.range(2)));
    settings.integrator.skipEmptySpace = state.range(3) != 0;
    for (auto _ : state) {
        const CloudLighting lighting(s.density, settings.medium, settings.sun.direction, s.sunBlocked());
        const CloudVolume volume(lighting, settings.medium, settings.integrator);
        benchmark::DoNotOptimize(renderFrame(s.frame(settings, &volume)));
    }
}
BENCHMARK(BM_RenderCloud)
    ->ArgNames({"w", "h", "spp", "skip"})
    ->Args({320, 180, 1, 1})
    ->Args({640, 360, 1, 0})
    ->Args({640, 360, 1, 1})
    ->Args({640, 360, 4, 1})
    ->Args({1280, 720, 1, 1})
    ->Args({1280, 720, 4, 1})
    ->Args({1920, 1080, 1, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// The same frame with the light scattered more than once traced by the
/// reference's paths (MultipleScatteringMethod::Paths), its lattice built
/// every iteration, as per frame.
void BM_RenderCloudPaths(benchmark::State& state)
{
    ShowcaseFrame& s = showcase();
    RenderSettings settings = s.settings(int(state.range(0)), int(state.range(1)), int(state.range(2)));
    settings.integrator.multipleScattering.method = MultipleScatteringMethod::Paths;
    for (auto _ : state) {
        const CloudLighting lighting(s.density, settings.medium, settings.sun.direction, s.sunBlocked());
        const CloudVolume volume(lighting, settings.medium, settings.integrator);
        benchmark::DoNotOptimize(renderFrame(s.frame(settings, &volume)));
    }
}
BENCHMARK(BM_RenderCloudPaths)->ArgNames({"w", "h", "spp"})->Args({640, 360, 1})->Unit(benchmark::kMillisecond)->UseRealTime();

/// The main job's frame 120 at 640x360, 1 spp, with its bank splatted from
/// `particles` particles (outside the timing): what the cloud's particle
/// count costs the render.
void BM_RenderMainJob(benchmark::State& state)
{
    const MainJobFrame& job = mainJobAtFrame120(state.range(0));
    const RenderSettings settings = job.settings(640, 360, 1);
    const openvdb::FloatGrid::Ptr density = splatParticles(job.simulator->particles(), job.scene.volume).density;
    const CloudLighting::Occlusion sunBlocked = [&job](const Vec3d& origin, const Vec3d& dir) {
        return job.surfaces->occluded(origin, dir, 1e-3, std::numeric_limits<double>::max());
    };
    for (auto _ : state) {
        const CloudLighting lighting(density, settings.medium, settings.sun.direction, sunBlocked);
        const CloudVolume volume(lighting, settings.medium, settings.integrator);
        benchmark::DoNotOptimize(renderFrame(job.frame(settings, &volume)));
    }
}
BENCHMARK(BM_RenderMainJob)->Apply(mainJobCounts)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace
