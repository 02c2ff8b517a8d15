// Benchmarks of the Embree back-end on the cloud showcase at frame 100: a
// surface-only frame, and a cloud frame with and without empty-space skipping.

#include <vfield/core/vdb_file.h>
#include <vfield/render/renderer.h>
#include <vfield/scene/scene.h>
#include <vfield/scene/simulation_run.h>

#include <benchmark/benchmark.h>

#include <filesystem>
#include <memory>

using namespace vfield;

namespace {

/// The showcase's surfaces and its frame-100 density (simulated once, into a temporary folder).
struct ShowcaseFrame {
    Scene scene = loadScene(VFIELD_SCENES_DIR "/cloud_over_terrain.json");
    SurfaceScene surfaces;
    openvdb::FloatGrid::Ptr density;

    ShowcaseFrame()
    {
        const std::string dir = (std::filesystem::temp_directory_path() / "vfield-bench-render").string();
        const std::string frame = dir + "/" + frameFileName("density", 100, "vdb");
        if (!std::filesystem::exists(frame)) {
            std::filesystem::remove_all(dir);
            simulateScene(scene, dir, {100, 100, {}});
        }
        density = openvdb::gridPtrCast<openvdb::FloatGrid>(readVdb(frame).at(0));
        surfaces.addStatic(0, makeMesh(scene.simulation.objects[0].mesh), scene.simulation.objects[0].transform);
        surfaces.commit();
    }

    FrameToRender frame(int width, int height, int spp, const CloudVolume* volume)
    {
        FrameToRender f;
        f.settings = &scene.render;
        f.surfaces = &surfaces;
        f.materials[0] = SurfaceMaterial::Terrain;
        f.volume = volume;
        f.width = width;
        f.height = height;
        f.samplesPerPixel = spp;
        f.frame = 100;
        f.camera = Camera::fromSettings(scene.render.camera, width, height);
        f.terrainLow = surfaces.staticBounds().min()[1];
        f.terrainHigh = surfaces.staticBounds().max()[1];
        return f;
    }
};

ShowcaseFrame& showcase()
{
    static ShowcaseFrame frame;
    return frame;
}

void BM_RenderSurfaces(benchmark::State& state)
{
    ShowcaseFrame& s = showcase();
    const FrameToRender frame = s.frame(int(state.range(0)), int(state.range(1)), int(state.range(2)), nullptr);
    for (auto _ : state) benchmark::DoNotOptimize(renderFrame(frame));
    state.counters["primary_rays_per_s"] =
        benchmark::Counter(double(state.range(0) * state.range(1) * state.range(2)), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_RenderSurfaces)->Args({640, 360, 1})->Args({640, 360, 4})->Args({1280, 720, 1})->Args({1280, 720, 4})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

/// A whole cloud frame: the volume's light grids are built every iteration, as per frame.
void BM_RenderCloud(benchmark::State& state)
{
    ShowcaseFrame& s = showcase();
    ImageSettings image = s.scene.render.image;
    image.skipEmptySpace = state.range(3) != 0;
    for (auto _ : state) {
        const CloudVolume volume(s.density, image, s.scene.render.sun.direction, &s.surfaces);
        benchmark::DoNotOptimize(renderFrame(s.frame(int(state.range(0)), int(state.range(1)), int(state.range(2)), &volume)));
    }
}
BENCHMARK(BM_RenderCloud)
    ->ArgNames({"w", "h", "spp", "skip"})
    ->Args({640, 360, 1, 0})->Args({640, 360, 1, 1})->Args({640, 360, 4, 1})->Args({1280, 720, 1, 1})->Args({1280, 720, 4, 1})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace
