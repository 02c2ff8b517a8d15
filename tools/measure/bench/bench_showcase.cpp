#include "bench_showcase.h"

#include <vfield/run/simulation_run.h>

#include <filesystem>
#include <limits>
#include <map>
#include <stdexcept>

namespace vfield::bench {

ShowcaseFrame::ShowcaseFrame() : scene(loadScene(VFIELD_SCENES_DIR "/cloud_over_terrain.json"))
{
    if (scene.render.image.samplesPerPixel != kShowcaseSamplesPerPixel)
        throw std::runtime_error("cloud_over_terrain.json renders " + std::to_string(scene.render.image.samplesPerPixel) +
                                 " samples a pixel, the benchmarks " + std::to_string(kShowcaseSamplesPerPixel) +
                                 ": update kShowcaseSamplesPerPixel");
    // Simulated once into a temporary folder, reused by later runs.
    const std::string dir = (std::filesystem::temp_directory_path() / "vfield-bench-render").string();
    const SimFolder folder(dir);
    if (!std::filesystem::exists(folder.densityFile(100))) {
        std::filesystem::remove_all(dir);
        simulateScene(scene, dir, SimulateOptions::writing(100, 100));
    }
    density = folder.readDensity(100);
    terrain = makeMesh(scene.simulation.objects[0].mesh);
    terrain.transform(scene.simulation.objects[0].transform.matrix());
    surfaces.addStatic(0, terrain, Transform{});
    surfaces.commit();
}

namespace {

RenderSettings sceneSettingsAt(const Scene& scene, int width, int height, int spp)
{
    RenderSettings settings = scene.render;
    settings.image.width = width;
    settings.image.height = height;
    settings.image.samplesPerPixel = spp;
    return settings;
}

/// A frame of terrain (object 0) and cloud, seen through the settings' camera.
FrameToRender terrainFrame(const RenderSettings& settings, const SurfaceScene& surfaces, const CloudVolume* volume, int frame)
{
    FrameToRender f;
    f.settings = &settings;
    f.surfaces = &surfaces;
    f.materials[0] = SurfaceMaterial::terrain();
    f.volume = volume;
    f.frame = frame;
    f.camera = Camera::fromSettings(settings.camera, settings.image.width, settings.image.height);
    f.terrainLow = surfaces.staticBounds().min()[1];
    f.terrainHigh = surfaces.staticBounds().max()[1];
    return f;
}

} // namespace

RenderSettings ShowcaseFrame::settings(int width, int height, int spp) const
{
    return sceneSettingsAt(scene, width, height, spp);
}

FrameToRender ShowcaseFrame::frame(const RenderSettings& settings, const CloudVolume* volume)
{
    return terrainFrame(settings, surfaces, volume, 100);
}

CloudLighting::Occlusion ShowcaseFrame::sunBlocked() const
{
    return [this](const Vec3d& origin, const Vec3d& dir) {
        return surfaces.occluded(origin, dir, 1e-3, std::numeric_limits<double>::max());
    };
}

ShowcaseFrame& showcase()
{
    static ShowcaseFrame frame;
    return frame;
}

MainJobFrame& mainJobAtFrame120(int64_t particles)
{
    static std::map<int64_t, MainJobFrame> cache;
    static SurfaceScene terrain;
    MainJobFrame& job = cache[particles];
    if (!job.simulator) {
        job.scene = loadScene(VFIELD_SCENES_DIR "/cloud_bank.json");
        const int64_t sceneParticles = job.scene.simulation.clouds[0].count;
        if (sceneParticles != kMainJobParticles)
            throw std::runtime_error("cloud_bank.json has " + std::to_string(sceneParticles) + " particles, the benchmarks " +
                                     std::to_string(kMainJobParticles) + ": update kMainJobParticles");
        // The cloud's mass kept, as a user changing its count would: the
        // same density from more or fewer particles.
        job.scene.volume.densityPerParticle *= double(sceneParticles) / double(particles);
        job.scene.simulation.clouds[0].count = particles;
        job.simulator = std::make_unique<Simulator>(job.scene.simulation);
        while (job.simulator->frame() < 120) job.simulator->advanceFrame();
        job.state = job.simulator->serializeState();
        if (terrain.staticBounds().empty()) {
            TriangleMesh mesh = job.simulator->objects()[0].mesh;
            mesh.transform(job.scene.simulation.objects[0].transform.matrix());
            terrain.addStatic(0, mesh, Transform{});
            terrain.commit();
        }
        job.surfaces = &terrain;
    }
    return job;
}

RenderSettings MainJobFrame::settings(int width, int height, int spp) const { return sceneSettingsAt(scene, width, height, spp); }

FrameToRender MainJobFrame::frame(const RenderSettings& settings, const CloudVolume* volume) const
{
    return terrainFrame(settings, *surfaces, volume, 120);
}

void mainJobCounts(benchmark::internal::Benchmark* benchmark)
{
    benchmark->ArgName("particles");
    for (const int64_t particles : {125'000, 250'000, 500'000, 1'000'000}) benchmark->Arg(particles);
}

} // namespace vfield::bench
