// Benchmarks of the simulation stage on the main job at frame 120: a frame of
// its advection, its density splat and its volume stage, the last two
// against OpenVDB's own rasterizer on the same particles.

#include "bench_showcase.h"

#include <vfield/run/frame_volume.h>
#include <vfield/sim/clearance.h>
#include <vfield/volume/density_splat.h>
#include <vfield/volume/particle_grid.h>

#include <openvdb/points/PointRasterizeFrustum.h>

#include <benchmark/benchmark.h>

#include <tbb/global_control.h>

#include <filesystem>
#include <map>
#include <memory>
#include <utility>

using namespace vfield;
using namespace vfield::bench;

namespace {

/// A frame of the main job's advection (swirls, fields, contacts and
/// adaptive substeps) from frame 120.
void BM_CloudFrame(benchmark::State& state)
{
    const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(1)));
    MainJobFrame& job = mainJobAtFrame120(state.range(0));
    uint64_t substeps = 0;
    for (auto _ : state) {
        state.PauseTiming();
        // Every iteration steps the same frame, 122, as a run does: after
        // frame 121, whose substeps leave caches a restored state lacks.
        job.simulator->restoreState(job.state);
        job.simulator->advanceFrame();
        state.ResumeTiming();
        job.simulator->advanceFrame();
        substeps += job.simulator->lastStep().substeps;
    }
    job.simulator->restoreState(job.state);
    state.counters["particle_steps_per_s"] = benchmark::Counter(double(substeps), benchmark::Counter::kIsRate);
    state.counters["particles"] = double(job.simulator->particles().size());
}
BENCHMARK(BM_CloudFrame)
    ->ArgNames({"particles", "threads"})
    ->Args({125'000, 2})
    ->Args({250'000, 2})
    ->Args({500'000, 2})
    ->Args({1'000'000, 1})
    ->Args({1'000'000, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// The splat alone (the deposit, its blur and the density and velocity
/// grids; no detail, no cutoff) of the main job's particles at frame 120.
void BM_DensitySplat(benchmark::State& state)
{
    MainJobFrame& job = mainJobAtFrame120(state.range(0));
    VolumeSettings volume = job.scene.volume;
    volume.detail.voxelSize = 0.0;
    volume.cutoff = 0.0;
    const ParticleSet& particles = job.simulator->particles();
    for (auto _ : state) benchmark::DoNotOptimize(splatParticles(particles, volume));
    state.SetItemsProcessed(state.iterations() * int64_t(particles.size()));
}
BENCHMARK(BM_DensitySplat)->Apply(mainJobCounts)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The detail stage alone (SplatSeconds::detail) on the lone cumulus
/// (scenes/features/cumulus.json) at frame 2, in each style: its splat's
/// density shaped by noise on the detail's finer grid.
void BM_DetailStage(benchmark::State& state)
{
    static const std::pair<Scene, std::unique_ptr<Simulator>> cumulus = [] {
        Scene scene = loadScene(VFIELD_SCENES_DIR "/features/cumulus.json");
        auto simulator = std::make_unique<Simulator>(scene.simulation);
        while (simulator->frame() < 2) simulator->advanceFrame();
        return std::make_pair(std::move(scene), std::move(simulator));
    }();
    VolumeSettings volume = cumulus.first.volume;
    volume.detail.style = DetailStyle(state.range(0));
    double detailSeconds = 0.0;
    std::size_t voxels = 0;
    for (auto _ : state) {
        SplatSeconds seconds;
        const DensityGrids grids = splatParticles(cumulus.second->particles(), volume, &seconds);
        detailSeconds += seconds.detail;
        voxels = grids.density->activeVoxelCount();
    }
    state.counters["detail_s"] = detailSeconds / double(state.iterations());
    state.counters["voxels"] = double(voxels);
}
BENCHMARK(BM_DetailStage)
    ->ArgName("style")
    ->Arg(int(DetailStyle::Billows))
    ->Arg(int(DetailStyle::Displaced))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// What a frame of the main job spends after its particles moved: the
/// splat, the detail, and writing the density and particle files.
void BM_VolumeStage(benchmark::State& state)
{
    MainJobFrame& frame = mainJobAtFrame120(state.range(0));
    const std::string dir = (std::filesystem::temp_directory_path() / "vfield-bench-volume").string();
    std::filesystem::create_directories(dir);
    const SimFolder folder(dir);
    const ParticleSet& particles = frame.simulator->particles();
    StageSeconds stages;
    for (auto _ : state) writeFrameVolume(folder, 120, particles, frame.scene.volume, 0, stages);
    state.counters["particles"] = double(particles.size());
    // Where the stage's time goes, seconds an iteration.
    const double iterations = double(state.iterations());
    state.counters["splat_s"] = stages.splat / iterations;
    state.counters["detail_s"] = stages.detail / iterations;
    state.counters["write_s"] = stages.write / iterations;
}
BENCHMARK(BM_VolumeStage)->Apply(mainJobCounts)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The main job's clearance measure: every particle against the terrain's
/// exact level set (its distance field built once, outside the timing).
void BM_Clearance(benchmark::State& state)
{
    MainJobFrame& frame = mainJobAtFrame120(state.range(0));
    static std::map<int64_t, std::unique_ptr<ClearanceProbe>> probes;
    std::unique_ptr<ClearanceProbe>& probe = probes[state.range(0)];
    if (!probe) probe = std::make_unique<ClearanceProbe>(*frame.simulator);
    for (auto _ : state) benchmark::DoNotOptimize(probe->measureParticles());
}
BENCHMARK(BM_Clearance)->Apply(mainJobCounts)->Unit(benchmark::kMillisecond)->UseRealTime();

/// OpenVDB's own splat of the main job's particles at frame 120 into the
/// grid the frame writes (its voxel, the detail's, with detailVoxel 1; the
/// splat's with 0): points::FrustumRasterizer on a linear transform, each
/// particle a sphere as wide as the splat's kernel, its uniform density
/// accumulated.
void BM_RawOpenVdbSplat(benchmark::State& state)
{
    MainJobFrame& frame = mainJobAtFrame120(state.range(0));
    const VolumeSettings volume = frame.scene.volume.resolved(frame.scene.simulation.clouds[0].particleRadius);
    const ParticleSet& particles = frame.simulator->particles();
    openvdb::points::PointDataGrid::Ptr points =
        openvdb::gridPtrCast<openvdb::points::PointDataGrid>(makeParticleGrid(particles, ParticlePrecision::Full));
    const double voxel = state.range(1) == 1 && volume.detail.enabled() ? volume.detail.voxelSize : volume.voxelSize;
    openvdb::points::FrustumRasterizerSettings settings(*openvdb::math::Transform::createLinearTransform(voxel));
    settings.useRadius = true; // pscale, the particle's radius
    settings.radiusScale = float(volume.kernelRadius / frame.scene.simulation.clouds[0].particleRadius);
    openvdb::points::FrustumRasterizer<openvdb::points::PointDataGrid> rasterizer(settings);
    openvdb::points::PointDataGrid::ConstPtr input = points;
    rasterizer.addPoints(input);
    for (auto _ : state) benchmark::DoNotOptimize(rasterizer.rasterizeUniformDensity(openvdb::points::RasterMode::ACCUMULATE));
    state.SetItemsProcessed(state.iterations() * int64_t(particles.size()));
    state.counters["voxel"] = voxel;
}
BENCHMARK(BM_RawOpenVdbSplat)
    ->ArgNames({"particles", "detailVoxel"})
    ->Args({1'000'000, 0})
    ->Args({1'000'000, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

} // namespace
