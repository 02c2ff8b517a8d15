// Each options struct declares its fields once (vfield/core/fields.h); these
// tests walk the declarations to prove that every field reaches what it must.

#include "field_mutator.h"
#include "test_meshes.h"

#include <vfield/folder/sim_folder.h>
#include <vfield/scene/inputs_hash.h>
#include <vfield/scene/scene.h>

#include <catch2/catch.hpp>

#include <OpenImageIO/imagebuf.h>
#include <vfield/core/image_file.h>

#include <fstream>
#include <iomanip>
#include <sstream>

using namespace vfield;

namespace {

/// A scene with every kind of object, cloud and field, every optional part
/// given, so that every declared field applies somewhere.
Scene everyKindOfScene()
{
    const std::string dir = test::scratchDir("options-every-kind");
    OIIO::ImageBuf heights(OIIO::ImageSpec(4, 4, 1, OIIO::TypeDesc::FLOAT));
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) heights.setpixel(x, y, std::vector<float>{0.1f * float(x + y)}.data());
    writeImage(heights, dir + "/heights.exr");
    std::ofstream(dir + "/scene.json") << R"({
      "version": 1, "frames": {"start": 2, "end": 30, "fps": 25}, "seed": 7,
      "objects": [
        {"name": "file", "mesh": {"file": ")" +
                                              test::dataPath("cube_quads.obj") + R"(", "tessellate": 0.5},
         "transform": {"translate": [1, 2, 3], "rotateDegrees": [10, 20, 30], "scale": 2}, "color": [0.1, 0.2, 0.3]},
        {"name": "terrain", "mesh": {"terrain": {"size": [100, 120], "cells": [16, 20], "style": "ridged", "erosion": 0.3,
          "carves": [{"path": [[0, 0], [10, 5], [20, 0]], "halfWidth": 8, "depth": 4, "wallSharpness": 2, "wallRoughness": 1,
                      "floorHeight": -3}]}},
         "repulsion": {"method": "distance", "voxelSize": 2, "margin": 5, "growth": "doubling"}},
        {"name": "heightmap", "mesh": {"heightmap": {"file": "heights.exr", "size": [50, 50], "cells": [8, 8]}}},
        {"name": "sphere", "mesh": {"sphere": {"center": [0, 40, 0], "radius": 3}}, "repulsion": false},
        {"name": "plane", "mesh": {"box": {"min": [-1, -1, -1], "max": [1, 2, 3]}}, "motion": "dynamic", "mass": 2,
         "drag": 0.1, "velocity": [5, 0, 0], "bank": true, "maxRollRate": 45, "maxPitchRate": 30}
      ],
      "clouds": [
        {"name": "a", "count": 100, "shape": "sphere", "radius": 4, "center": [0, 50, 0], "billow": 0.3, "billowSize": 2},
        {"name": "b", "count": 100, "shape": "ellipsoid", "radii": [4, 5, 6], "center": [0, 60, 0]},
        {"name": "c", "count": 100, "shape": "box", "halfSize": [4, 5, 6], "center": [0, 70, 0], "velocity": [1, 0, 0]}
      ],
      "fields": [
        {"name": "wind", "acceleration": [1, 0, 0], "box": {"min": [-50, 0, -50], "max": [50, 80, 50]}, "softEdge": 5,
         "affects": ["a", "plane"]},
        {"name": "gravity", "acceleration": [0, -9.8, 0]}
      ],
      "simulation": {"sampling": "trilinear", "cfl": 0.4, "restPeriod": 8,
                     "domain": {"min": [-100, -100, -100], "max": [100, 100, 100]}},
      "volume": {"voxelSize": 0.5, "kernelRadius": 1, "densityPerParticle": 2,
                 "detail": {"voxelSize": 0.25, "edgeSoftness": 0.1}},
      "camera": {"follow": {"object": "plane"}}
    })";
    return loadScene(dir + "/scene.json");
}

/// The JSON with every number rounded to 12 significant digits: Euler angles
/// read back from a quaternion differ in the last bits.
nlohmann::json rounded(const nlohmann::json& json)
{
    if (json.is_number_float()) {
        std::ostringstream text;
        text << std::setprecision(12) << json.get<double>();
        return std::stod(text.str());
    }
    if (json.is_object() || json.is_array()) {
        nlohmann::json out = json;
        for (auto& item : out) item = rounded(item);
        return out;
    }
    return json;
}

} // namespace

TEST_CASE("options: every field that shapes a simulation changes its inputs hash, one at a time", "[options]")
{
    const Scene scene = everyKindOfScene();
    const uint64_t base = simulationInputsHash(scene.simulation, scene.volume);
    const int setupFields = test::countFields(scene.simulation), volumeFields = test::countFields(scene.volume);
    CHECK(setupFields > 120); // every kind of object, cloud and field
    for (int k = 0; k < setupFields; ++k) {
        std::string key;
        const SimulationSettings changed = test::withFieldChanged(scene.simulation, k, key);
        INFO("simulation field " << k << ": " << key);
        CHECK(simulationInputsHash(changed, scene.volume) != base);
    }
    for (int k = 0; k < volumeFields; ++k) {
        std::string key;
        const VolumeSettings changed = test::withFieldChanged(scene.volume, k, key);
        INFO("volume field " << k << ": " << key);
        CHECK(simulationInputsHash(scene.simulation, changed) != base);
    }
}

TEST_CASE("options: an edited mesh file or elevation image changes the inputs hash", "[options]")
{
    Scene scene = everyKindOfScene();
    const uint64_t base = simulationInputsHash(scene.simulation, scene.volume);
    const std::string heights = scene.simulation.objects[2].mesh.heightmap.path;
    std::ofstream(heights, std::ios::app) << " ";
    CHECK(simulationInputsHash(scene.simulation, scene.volume) != base);
}

TEST_CASE("options: how a scene is seen leaves its inputs hash alone and changes the render stamp, field by field", "[options]")
{
    const Scene scene = everyKindOfScene();
    const uint64_t simulation = simulationInputsHash(scene.simulation, scene.volume);
    const uint64_t stamp = scene.render.hash();
    const int fields = test::countFields(scene.render);
    CHECK(fields > 30);
    for (int k = 0; k < fields; ++k) {
        std::string key;
        Scene changed = scene;
        changed.render = test::withFieldChanged(scene.render, k, key);
        INFO("render field " << k << ": " << key);
        CHECK(changed.render.hash() != stamp);
        CHECK(simulationInputsHash(changed.simulation, changed.volume) == simulation);
    }
}

TEST_CASE("options: a scene written from its declaration reads back the same", "[options]")
{
    const Scene scene = everyKindOfScene();
    const nlohmann::json written = fieldsToJson(scene);
    const Scene read = parseScene(written.dump(1), scene.path);
    CHECK(rounded(fieldsToJson(read)).dump(1) == rounded(written).dump(1));
    CHECK(read.render.hash() == scene.render.hash());
}
