// A render whose light is gathered over frames (the fast integrator's paths
// of the frames around each one) gives each frame the same image however its
// range is cut: rendered whole, in parts, or resumed; a simulation of a few
// frames renders from those.

#include "sim_test_scenes.h"
#include "test_meshes.h"

#include <vfield/core/frame_file.h>
#include <vfield/image/image_compare.h>
#include <vfield/run/render_run.h>
#include <vfield/run/simulation_run.h>

#include <catch2/catch.hpp>

using namespace vfield;

namespace {

/// The main job's bank, small and moving, lit by paths gathered over three frames.
Scene bankWithPathsAround(int frames)
{
    Scene scene = test::showcaseAtTestResolution("cloud_bank.json", 20000, frames);
    scene.simulation.objects.clear();
    scene.render.image.width = 80;
    scene.render.image.height = 45;
    scene.render.image.samplesPerPixel = 1;
    scene.render.camera.position = Vec3d(140.28, 77.82, 39.3);
    scene.render.camera.lookAt = Vec3d(-50.2, 30.2, 1.2);
    scene.render.integrator.multipleScattering.method = MultipleScatteringMethod::Paths;
    scene.render.integrator.multipleScattering.pathsPerFrame = 3000;
    scene.render.integrator.multipleScattering.pathFramesAround = 1;
    return scene;
}

double maxError(const std::string& a, const std::string& b, int frame)
{
    const std::string name = frameFileName("frame", frame, "png");
    INFO(name);
    return compareImages(a + "/" + name, b + "/" + name).maxError;
}

} // namespace

TEST_CASE("render: light gathered over frames gives a frame the same image rendered whole, in parts or resumed", "[run][render]")
{
    const Scene scene = bankWithPathsAround(6);
    const std::string dir = test::scratchDir("render-frames-around");
    simulateScene(scene, dir + "/sim");
    const RenderRunSummary whole = renderScene(scene, dir + "/sim", dir + "/whole", {});
    CHECK(whole.rendered == 6);

    // Frames 3-4 alone look at 2 and 5 themselves; frame 6, the last, gathers 4-6.
    RenderRunOptions middle;
    middle.firstFrame = 3;
    middle.lastFrame = 4;
    renderScene(scene, dir + "/sim", dir + "/parts", middle);
    RenderRunOptions end;
    end.firstFrame = end.lastFrame = 6;
    renderScene(scene, dir + "/sim", dir + "/parts", end);
    for (int frame : {3, 4, 6}) CHECK(maxError(dir + "/whole", dir + "/parts", frame) == 0.0);

    // A render stopped after frame 2 and run again renders the rest as the whole did.
    RenderRunOptions firstTwo;
    firstTwo.lastFrame = 2;
    renderScene(scene, dir + "/sim", dir + "/resumed", firstTwo);
    const RenderRunSummary resumed = renderScene(scene, dir + "/sim", dir + "/resumed", {});
    CHECK(resumed.skipped == 2);
    for (int frame = 1; frame <= 6; ++frame) CHECK(maxError(dir + "/whole", dir + "/resumed", frame) == 0.0);

    // The light does gather over frames: frame 3 alone differs.
    Scene alone = scene;
    alone.render.integrator.multipleScattering.pathFramesAround = 0;
    renderScene(alone, dir + "/sim", dir + "/alone", middle);
    CHECK(maxError(dir + "/whole", dir + "/alone", 3) > 0.0);
}

TEST_CASE("render: light gathered over frames comes from the frames simulated, and again when more are", "[run][render]")
{
    const Scene scene = bankWithPathsAround(6);
    const std::string dir = test::scratchDir("render-frames-simulated");
    SimulateOptions firstTwo;
    firstTwo.lastFrame = 2;
    simulateScene(scene, dir + "/sim", firstTwo);
    RenderRunOptions render;
    render.lastFrame = 2;
    CHECK(renderScene(scene, dir + "/sim", dir + "/frames", render).rendered == 2);

    CHECK(renderScene(scene, dir + "/sim", dir + "/frames", render).skipped == 2);

    // Simulated on to frame 6, both gather frames 1-3 and are rendered again,
    // as the whole range renders them.
    simulateScene(scene, dir + "/sim");
    CHECK(renderScene(scene, dir + "/sim", dir + "/frames", render).rendered == 2);
    renderScene(scene, dir + "/sim", dir + "/whole", {});
    for (int frame : {1, 2}) CHECK(maxError(dir + "/whole", dir + "/frames", frame) == 0.0);
}

TEST_CASE("render: a frame of a keyed camera, sun and sky is the frame their values there render", "[run][render][keys]")
{
    Scene keyed = bankWithPathsAround(3);
    keyed.render.integrator.multipleScattering.pathFramesAround = 0;
    const Vec3d from = keyed.render.camera.position;
    keyed.render.camera.animation.set("position",
                                      KeyTrack({1.0, 3.0}, {from[0], from[1], from[2], from[0] - 30.0, from[1] + 10.0, from[2]},
                                               3, Interpolation::Smooth, false));
    keyed.render.sun.animation.set("direction",
                                   KeyTrack({1.0, 3.0}, {0.3, 0.8, 0.5, -0.5, 0.6, 0.6}, 3, Interpolation::Linear, true));
    keyed.render.sky.animation.set("intensity", KeyTrack({1.0, 3.0}, {1.0, 0.4}, 1, Interpolation::Linear, false));
    const std::string dir = test::scratchDir("render-keys");
    simulateScene(keyed, dir + "/sim");
    RenderRunOptions second;
    second.firstFrame = second.lastFrame = 2;
    renderScene(keyed, dir + "/sim", dir + "/keyed", second);

    Scene constant = keyed;
    constant.render = keyed.render.at(2.0);
    CHECK(constant.render.camera.position != from);
    renderScene(constant, dir + "/sim", dir + "/constant", second);
    CHECK(maxError(dir + "/keyed", dir + "/constant", 2) == 0.0);
    // The keys do change the frame.
    Scene first = keyed;
    first.render = keyed.render.at(1.0);
    renderScene(first, dir + "/sim", dir + "/first", second);
    CHECK(maxError(dir + "/keyed", dir + "/first", 2) > 0.0);
}
