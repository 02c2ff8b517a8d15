// A scene simulated and rendered in one run, the renderer following the
// simulation frame by frame, writes what a simulation and then a render
// write, resumes as they do, and stops both stages on either's error.

#include "sim_test_scenes.h"
#include "test_meshes.h"

#include <vfield/core/frame_file.h>
#include <vfield/image/grid_compare.h>
#include <vfield/image/image_compare.h>
#include <vfield/run/scene_run.h>

#include <catch2/catch.hpp>

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <stdexcept>

using namespace vfield;

namespace {

/// The airplane through its cloud, small: the airplane is in view, so every
/// frame's image needs its track as far as that frame.
Scene smallRunScene(int frames = 8)
{
    Scene scene = test::showcaseAtTestResolution("plane_through_cloud.json", 2000, frames);
    scene.render.image.width = 96;
    scene.render.image.height = 54;
    scene.render.image.samplesPerPixel = 1;
    scene.render.camera.lookAt = Vec3d(-76.0, 8.0, 0.0); // where it flies in the first frames
    // The paths' lattice costs as much at any image size.
    scene.render.integrator.multipleScattering.method = MultipleScatteringMethod::Octaves;
    return scene;
}

} // namespace

TEST_CASE("run: the renderer follows the simulation and writes the images a simulation and then a render write", "[run][render]")
{
    const Scene scene = smallRunScene();
    const std::string apart = test::scratchDir("run-apart"), together = test::scratchDir("run-together");
    simulateScene(scene, apart + "/sim");
    // EXR frames too: their motion vectors, like the shutter's close, see the next frame's poses.
    RenderRunOptions render;
    render.formats = {"png", "exr"};
    const RenderRunSummary separate = renderScene(scene, apart + "/sim", apart, render);
    // After each frame the simulation waits for the renderer to finish the
    // frame before it, so the renderer is at most a frame behind: a frame
    // that needs the next one's poses must wait for them.
    std::mutex mutex;
    std::condition_variable rendered;
    int renderedThrough = 0;
    RenderRunOptions beside = render;
    beside.progress = [&](int frame, int, int, double) {
        {
            const std::lock_guard<std::mutex> lock(mutex);
            renderedThrough = frame;
        }
        rendered.notify_all();
    };
    SimulateOptions simulate;
    simulate.progress = [&](const FrameProgress& progress) {
        std::unique_lock<std::mutex> lock(mutex);
        rendered.wait_for(lock, std::chrono::seconds(60), [&] { return renderedThrough >= progress.frame - 1; });
    };
    const SceneRunSummary run = runScene(scene, together, simulate, beside);
    CHECK(run.render.rendered == separate.rendered);
    CHECK(run.simulation.frames.size() == 8);
    for (int frame = 1; frame <= 8; ++frame) {
        for (const char* format : {"png", "exr"}) {
            const std::string name = frameFileName("frame", frame, format);
            INFO(name);
            CHECK(compareImages(apart + "/" + name, together + "/" + name).maxError == 0.0);
        }
        const SimFolder a(apart + "/sim"), b(together + "/sim");
        CHECK(compareGridFiles(a.densityFile(frame), b.densityFile(frame)).equal());
        CHECK(compareGridFiles(a.particlesFile(frame), b.particlesFile(frame)).equal());
    }

    // Run again: both stages find their frames complete.
    const SceneRunSummary rerun = runScene(scene, together, {}, render);
    CHECK(rerun.render.rendered == 0);
    CHECK(rerun.render.skipped == 8);
}

TEST_CASE("run: a render that fails stops the simulation, and its error is the one thrown", "[run][render]")
{
    // Forty frames: a frame of the render costs about as much as one of the
    // simulation (the density's lighting is built at its 0.2-unit detail
    // voxels whatever the image's size), and with eight the simulation could
    // finish before the render failed at its second.
    const Scene scene = smallRunScene(40);
    const std::string dir = test::scratchDir("run-render-fails");
    RenderRunOptions render;
    render.progress = [](int frame, int, int, double) {
        if (frame == 2) throw std::runtime_error("the render broke at frame 2");
    };
    CHECK_THROWS_WITH(runScene(scene, dir, {}, render), "the render broke at frame 2");
    // Stopped at its next frame, not run to the end (a frame or two ahead of the render at most).
    CHECK(SimFolder(dir + "/sim").readStats().frames.size() < 40);
}

TEST_CASE("run: a simulation that fails stops the render, and its error is the one thrown", "[run][render]")
{
    const Scene scene = smallRunScene();
    const std::string dir = test::scratchDir("run-simulation-fails");
    SimulateOptions simulate;
    simulate.progress = [](const FrameProgress& progress) {
        if (progress.frame == 3) throw std::runtime_error("the simulation broke at frame 3");
    };
    CHECK_THROWS_WITH(runScene(scene, dir, simulate, {}), "the simulation broke at frame 3");
    // The render waits for frame 4, which never comes, and stops there.
    CHECK_FALSE(std::filesystem::exists(dir + "/" + frameFileName("frame", 4, "png")));
}
