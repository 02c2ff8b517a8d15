#include "test_meshes.h"

#include <vfield/core/error.h>
#include <vfield/scene/scene.h>

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

using namespace vfield;

namespace {

const std::string kObjects = R"("objects": [{"name": "ground", "mesh": {"box": {"min": [-1, -1, -1], "max": [1, 0, 1]}}}])";

Scene sceneWith(const std::string& body) { return parseScene("{\"version\": 1, " + kObjects + body + "}", "s.json"); }

} // namespace

TEST_CASE("scene: defaults fill everything but the objects", "[scene]")
{
    const Scene scene = sceneWith("");
    CHECK(scene.simulation.firstFrame == 1);
    CHECK(scene.simulation.lastFrame == 120);
    CHECK(scene.simulation.fps == 24.0);
    CHECK(scene.simulation.objects.size() == 1);
    CHECK(scene.simulation.objects[0].repulsion.has_value());
    CHECK(scene.render.image.width == 640);
    CHECK(scene.simulation.solver.sampling == SolverSettings::Sampling::Dual);
}

TEST_CASE("scene: the shipped scenes parse", "[scene]")
{
    int scenes = 0;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(VFIELD_SCENES_DIR)) {
        if (entry.path().extension() != ".json") continue;
        INFO(entry.path().string());
        const Scene scene = loadScene(entry.path().string());
        CHECK_FALSE((scene.simulation.objects.empty() && scene.simulation.clouds.empty())); // something to animate
        ++scenes;
    }
    CHECK(scenes >= 8);
    // The bank's terrain field doubles; a growth of another name is refused with its JSON path.
    const Scene bank = loadScene(std::string(VFIELD_SCENES_DIR) + "/cloud_bank.json");
    CHECK(bank.simulation.objects.at(0).repulsion->field.growth == MagnitudeGrowth::Doubling);
    CHECK_THROWS_WITH(
        parseScene(R"({"version": 1, "objects": [{"name": "g", "mesh": {"box": {"min": [0, 0, 0], "max": [1, 1, 1]}},
                                                              "repulsion": {"growth": "cubic"}}]})",
                   "s.json"),
        Catch::Contains("/objects/0/repulsion/growth"));
}

TEST_CASE("scene: bad values are refused with their JSON path", "[scene]")
{
    CHECK_THROWS_WITH(sceneWith(R"(, "clouds": [{"count": -5}])"),
                      "s.json: /clouds/0/count: expected a positive integer, got -5");
    CHECK_THROWS_WITH(sceneWith(R"(, "clouds": [{"cuont": 5}])"), "s.json: /clouds/0/cuont: unknown key \"cuont\"");
    CHECK_THROWS_WITH(sceneWith(R"(, "clouds": [{"billow": 1}])"), Catch::Contains("/clouds/0/billow"));
    CHECK_THROWS_WITH(sceneWith(R"(, "frames": {"start": 10, "end": 2})"), Catch::Contains("/frames: \"end\" comes before"));
    CHECK_THROWS_WITH(sceneWith(R"(, "simulation": {"sampling": "cubic"})"), Catch::Contains("/simulation/sampling"));
    CHECK_THROWS_WITH(sceneWith(R"(, "simulation": {"restPeriod": 5})"),
                      "s.json: /simulation/restPeriod: restPeriod must be an even number of frames (or 0), not 5");
    CHECK_THROWS_WITH(sceneWith(R"(, "camera": {"follow": {"object": "ground"}})"), Catch::Contains("not a dynamic object"));
    CHECK_THROWS_WITH(sceneWith(R"(, "render": {"integrator": "pathtracer"})"),
                      "s.json: /render/integrator: expected one of \"fast\", \"reference\", got \"pathtracer\"");
    CHECK_THROWS_WITH(sceneWith(R"(, "render": {"maxBounces": 0})"), Catch::Contains("/render/maxBounces"));
    CHECK_THROWS_WITH(sceneWith(R"(, "fields": [{"acceleration": [1, 0, 0], "affects": ["ground"]}])"),
                      "s.json: /fields/0/affects/0: no dynamic object or cloud is named \"ground\"");
    CHECK_THROWS_WITH(
        parseScene(R"({"version": 1, "objects": [{"name": "a", "mesh": {"box": {}}, "color": [2, 0, 0]}]})", "s.json"),
        Catch::Contains("/objects/0/color/0"));
    CHECK_THROWS_WITH(parseScene(R"({"version": 2, "objects": []})", "s.json"), Catch::Contains("/version"));
    CHECK_THROWS_WITH(parseScene(R"({"version": 1})", "s.json"), "s.json: /: missing key \"objects\"");
    CHECK_THROWS_WITH(parseScene(R"({"version": 1, "objects": [{"name": "a", "mesh": {"box": {}}, "mass": 3}]})", "s.json"),
                      Catch::Contains("/objects/0/mass: \"mass\" applies to dynamic objects only"));
}

TEST_CASE("scene: a potential flow is refused where nothing in it would push", "[scene]")
{
    const std::string flow = R"({"name": "hill", "mesh": {"box": {}}, "repulsion": {"method": "potentialFlow"}})";
    const std::string plane = R"({"name": "plane", "mesh": {"box": {}}, "motion": "dynamic"})";
    CHECK_THROWS_WITH(parseScene(R"({"version": 1, "objects": [)" + flow + ", " + plane + "]}", "s.json"),
                      "s.json: /objects/0/repulsion/method: potentialFlow acts on clouds only, and dynamic object "
                      "\"plane\" would pass through it");
    CHECK_THROWS_WITH(parseScene(R"({"version": 1, "objects": [)" + flow + R"(], "clouds": [{"drag": 0}]})", "s.json"),
                      Catch::Contains("/clouds/0/drag: a potential flow carries particles"));
    CHECK_THROWS_WITH(
        parseScene(R"({"version": 1, "objects": [{"name": "a", "mesh": {"box": {}}, "repulsion": {"method": "sdf"}}]})",
                   "s.json"),
        Catch::Contains("/objects/0/repulsion/method"));
    CHECK_THROWS_WITH(
        parseScene(R"({"version": 1, "objects": [{"name": "a", "mesh": {"box": {}}, "repulsion": {"voxelSize": 0.1}}]})",
                   "s.json"),
        Catch::Contains("/objects/0/repulsion/voxelSize: applies to the distance and potentialFlow methods"));
}

TEST_CASE("scene: absurd sizes are refused before anything is allocated", "[scene]")
{
    CHECK_THROWS_WITH(sceneWith(R"(, "clouds": [{"count": 100000000000}])"), Catch::Contains("/clouds/0/count"));
    CHECK_THROWS_WITH(sceneWith(R"(, "clouds": [{"count": 30000000}, {"count": 30000000}])"),
                      Catch::Contains("/clouds/1: the clouds ask for more than"));
    CHECK_THROWS_WITH(sceneWith(R"(, "clouds": [{"radius": 1000}], "volume": {"voxelSize": 0.001})"),
                      Catch::Contains("raise volume.voxelSize"));
    CHECK_THROWS_WITH(
        parseScene(R"({"version": 1, "objects": [{"name": "t", "mesh": {"terrain": {"cells": [100000, 10]}}}]})", "s.json"),
        Catch::Contains("/objects/0/mesh/terrain/cells/0"));
}

TEST_CASE("scene: an override's * stands for every element, passing objects without a field", "[scene]")
{
    const std::string dir = test::scratchDir("scene-wildcard");
    std::ofstream(dir + "/s.json") << R"({"version": 1, "objects": [
        {"name": "a", "mesh": {"box": {}}},
        {"name": "b", "mesh": {"box": {}}, "repulsion": false},
        {"name": "c", "mesh": {"box": {}}, "repulsion": {"strength": 3}},
        {"name": "d", "mesh": {"box": {}}, "repulsion": true}]})";
    const Scene scene = loadScene(dir + "/s.json", {{"/objects/*/repulsion/splitRule", "\"paper\""}});
    const std::vector<ObjectSettings>& objects = scene.simulation.objects;
    CHECK(objects[0].repulsion->field.splitRule == SplitRule::Paper);
    CHECK_FALSE(objects[1].repulsion.has_value());
    CHECK(objects[2].repulsion->field.splitRule == SplitRule::Paper);
    CHECK(objects[2].repulsion->field.strength == 3.0);
    CHECK(objects[3].repulsion->field.splitRule == SplitRule::Paper);
    // Without a *, a place that cannot hold the value is an error; a bad value is the scene's error.
    CHECK_THROWS_WITH(loadScene(dir + "/s.json", {{"/objects/1/repulsion/splitRule/x", "1"}}),
                      Catch::Contains("no such place in the scene"));
    CHECK_THROWS_WITH(loadScene(dir + "/s.json", {{"/objects/*/repulsion/splitRule", "\"cone\""}}),
                      Catch::Contains("s.json: /objects/0/repulsion/splitRule: expected one of"));
    CHECK_THROWS_WITH(loadScene(dir + "/s.json", {{"/objects/0/*", "1"}}),
                      Catch::Contains("stands for the elements of an array"));
}

TEST_CASE("scene: a mesh file path is relative to the scene file", "[scene]")
{
    const std::string dir = test::scratchDir("scene-paths");
    std::ofstream(dir + "/scene.json") << R"({"version": 1, "objects": [{"name": "m", "mesh": {"file": "meshes/m.obj"}}]})";
    const Scene scene = loadScene(dir + "/scene.json");
    CHECK(scene.simulation.objects[0].mesh.path == dir + "/meshes/m.obj");
    CHECK_THROWS_WITH(loadScene(dir + "/none.json"), dir + "/none.json: no such file");
}
