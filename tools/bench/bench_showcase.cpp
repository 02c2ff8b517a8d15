#include "bench_showcase.h"

#include <vfield/core/vdb_file.h>
#include <vfield/scene/simulation_run.h>

#include <filesystem>
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
    const std::string frame = dir + "/" + frameFileName("density", 100, "vdb");
    if (!std::filesystem::exists(frame)) {
        std::filesystem::remove_all(dir);
        simulateScene(scene, dir, {100, 100, {}});
    }
    density = openvdb::gridPtrCast<openvdb::FloatGrid>(readVdb(frame).at(0));
    terrain = makeMesh(scene.simulation.objects[0].mesh);
    terrain.transform(scene.simulation.objects[0].transform.matrix());
    surfaces.addStatic(0, terrain, Transform{});
    surfaces.commit();
}

FrameToRender ShowcaseFrame::frame(int width, int height, int spp, const CloudVolume* volume)
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

ShowcaseFrame& showcase()
{
    static ShowcaseFrame frame;
    return frame;
}

} // namespace vfield::bench
