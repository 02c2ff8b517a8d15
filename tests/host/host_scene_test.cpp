#include "test_meshes.h"

#include <vfield/folder/sim_folder.h>
#include <vfield/host/host_scene.h>
#include <vfield/mesh/mesh_io.h>
#include <vfield/run/simulation_run.h>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

using namespace vfield;
namespace fs = std::filesystem;

namespace {

/// A painted block on the ground and a box coasting past it, a puff of cloud
/// above; the camera fixed, keyed or following the box; more keys after it.
Scene blockAndBox(const std::string& camera, const std::string& moreKeys = "")
{
    return parseScene(R"({"version": 1, "frames": {"start": 3, "end": 14, "fps": 24},
      "objects": [{"name": "block / ground", "mesh": {"box": {}}, "color": [0.2, 0.4, 0.6], "repulsion": false,
                   "transform": {"translate": [5, -20, 0], "scale": 3}},
                  {"name": "box", "mesh": {"box": {}}, "motion": "dynamic", "repulsion": false, "velocity": [10, 0, 0]}],
      "clouds": [{"name": "puff", "count": 300, "center": [0, 10, 0], "radius": 3}],
      "camera": )" + camera +
                          moreKeys +
                          R"(,
      "render": {"resolution": [64, 36], "extinction": 0.7, "albedo": 0.8},
      "simulation": {"domain": {"min": [-100, -100, -100], "max": [100, 100, 100]}}})",
                      "block_and_box.json");
}

nlohmann::json readHost(const SimFolder& sim)
{
    std::ifstream in(hostSceneDir(sim) + "/host.json");
    return nlohmann::json::parse(in);
}

Vec3d vec(const nlohmann::json& v) { return Vec3d(v[0].get<double>(), v[1].get<double>(), v[2].get<double>()); }

} // namespace

TEST_CASE("host scene: what a host rebuilds the scene from, meshes placed as the renderer places them", "[scene][host]")
{
    const Scene scene = blockAndBox(R"({"position": [0, 5, 60], "lookAt": [0, 0, 0], "fovDegrees": 40})");
    const SimFolder sim(test::scratchDir("host-fixed"));
    simulateScene(scene, sim.path());
    writeHostScene(scene, sim);
    const nlohmann::json host = readHost(sim);
    const fs::path dir = hostSceneDir(sim);

    CHECK(host["frames"] == nlohmann::json({3, 14}));
    CHECK(host["fps"] == 24.0);
    CHECK(fs::exists(dir / "../density.0014.vdb"));
    CHECK(fs::equivalent(dir / host["tracks"].get<std::string>(), sim.tracksFile()));
    std::string pattern = host["volume"]["files"];
    CHECK(fs::equivalent(dir / pattern.replace(pattern.find("####"), 4, "0007"), sim.densityFile(7)));
    CHECK(host["volume"]["extinction"] == 0.7);
    CHECK(host["volume"]["albedo"] == 0.8);

    REQUIRE(host["objects"].size() == 2);
    const nlohmann::json& block = host["objects"][0];
    CHECK(block["space"] == "world");
    CHECK(block["material"]["kind"] == "painted");
    CHECK(vec(block["material"]["color"]) == Vec3d(0.2, 0.4, 0.6));
    // The static block as placed (the box [-1, 1]^3 scaled 3 about the origin, moved), the box in its own space.
    const BBoxd placed = loadMesh((dir / block["mesh"].get<std::string>()).string()).bounds();
    CHECK(placed.min().eq(Vec3d(5 - 3, -20 - 3, -3), 1e-6));
    CHECK(placed.max().eq(Vec3d(5 + 3, -20 + 3, 3), 1e-6));
    CHECK(host["objects"][1]["space"] == "object");
    CHECK(loadMesh((dir / host["objects"][1]["mesh"].get<std::string>()).string()).bounds().max().eq(Vec3d(1.0), 1e-6));

    REQUIRE(host["camera"]["poses"].size() == 1);
    CHECK(vec(host["camera"]["poses"][0]["position"]) == Vec3d(0, 5, 60));
    CHECK(host["camera"]["fovDegrees"] == 40.0);
    CHECK(host["camera"]["resolution"] == nlohmann::json({64, 36}));
}

TEST_CASE("host scene: a following camera gets a pose per frame, looking at the object", "[scene][host]")
{
    const Scene scene = blockAndBox(R"({"follow": {"object": "box", "offset": [-20, 5, 0]}})");
    const SimFolder sim(test::scratchDir("host-follow"));
    simulateScene(scene, sim.path());
    writeHostScene(scene, sim);
    const nlohmann::json poses = readHost(sim)["camera"]["poses"];
    const Tracks tracks = sim.readTracks();
    REQUIRE(poses.size() == 12);
    for (int i = 0; i < 12; ++i) {
        const nlohmann::json& pose = poses[std::size_t(i)];
        CHECK(pose["frame"] == 3 + i);
        const Vec3d position = vec(pose["position"]), box = tracks.pose("box", 3 + i).translation;
        const Vec3d looking = (vec(pose["lookAt"]) - position).unitSafe();
        CHECK(looking.dot((box - position).unitSafe()) == Approx(1.0).epsilon(1e-9));
        CHECK((box - position).length() == Approx(std::sqrt(20.0 * 20.0 + 5.0 * 5.0)).epsilon(1e-6));
    }
}

TEST_CASE("host scene: a keyed camera and sun get their values at every frame", "[scene][host][keys]")
{
    const Scene scene = blockAndBox(R"({"position": {"keys": [[3, [0, 5, 60]], [14, [22, 5, 60]]]}, "lookAt": [0, 0, 0],
                                        "fovDegrees": {"keys": [[3, 40], [14, 62]]}})",
                                    R"(, "sun": {"intensity": {"keys": [[3, 1], [14, 12]]}})");
    const SimFolder sim(test::scratchDir("host-keys"));
    simulateScene(scene, sim.path());
    writeHostScene(scene, sim);
    const nlohmann::json host = readHost(sim);
    const nlohmann::json& poses = host["camera"]["poses"];
    const nlohmann::json& suns = host["sun"]["frames"];
    REQUIRE(poses.size() == 12);
    REQUIRE(suns.size() == 12);
    for (int i = 0; i < 12; ++i) {
        const nlohmann::json& pose = poses[std::size_t(i)];
        CHECK(pose["frame"] == 3 + i);
        CHECK((vec(pose["position"]) - Vec3d(2.0 * i, 5, 60)).length() < 1e-9);
        CHECK(pose["fovDegrees"].get<double>() == Approx(40.0 + 2.0 * i));
        CHECK(suns[std::size_t(i)]["frame"] == 3 + i);
        CHECK(suns[std::size_t(i)]["intensity"].get<double>() == Approx(1.0 + i));
    }
}

TEST_CASE("host scene: a folder without finished frames is refused, naming stats.json", "[scene][host]")
{
    const SimFolder sim(test::scratchDir("host-empty"));
    CHECK_THROWS_WITH(writeHostScene(blockAndBox(R"({"position": [0, 5, 60]})"), sim), Catch::Contains("stats.json"));
}
