#include "bench_showcase.h"

#include <vfield/scene/simulation_run.h>

#include <filesystem>
#include <limits>
#include <map>

namespace vfield::bench {

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

ShowcaseFrame::ShowcaseFrame() : scene(loadScene(VFIELD_SCENES_DIR "/cloud_over_terrain.json"))
{
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

RenderSettings ShowcaseFrame::settings(int width, int height, int spp) const
{
    RenderSettings settings = scene.render;
    settings.image.width = width;
    settings.image.height = height;
    settings.image.samplesPerPixel = spp;
    return settings;
}

FrameToRender ShowcaseFrame::frame(const RenderSettings& settings, const CloudVolume* volume)
{
    FrameToRender f;
    f.settings = &settings;
    f.surfaces = &surfaces;
    f.materials[0] = SurfaceMaterial::terrain();
    f.volume = volume;
    f.frame = 100;
    f.camera = Camera::fromSettings(settings.camera, settings.image.width, settings.image.height);
    f.terrainLow = surfaces.staticBounds().min()[1];
    f.terrainHigh = surfaces.staticBounds().max()[1];
    return f;
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

} // namespace vfield::bench
