#include "sim_test_scenes.h"

#include <nlohmann/json.hpp>

#include <fstream>

namespace vfield::test {

Scene singleParticleScene(const std::string& fieldsJson, int frames, double drag, double fps)
{
    const std::string text = R"({
      "version": 1, "frames": {"start": 1, "end": )" +
                             std::to_string(frames) + R"(, "fps": )" + std::to_string(fps) + R"(},
      "objects": [],
      "clouds": [{"count": 1, "shape": "box", "center": [0, 0, 0], "halfSize": [1e-9, 1e-9, 1e-9],
                  "drag": )" +
                             std::to_string(drag) + R"(}],
      "fields": )" + fieldsJson +
                             R"(,
      "simulation": {"domain": {"min": [-1e6, -1e6, -1e6], "max": [1e6, 1e6, 1e6]}}
    })";
    return parseScene(text, "particle.json");
}

Scene showcaseAtTestResolution(const std::string& name, int particles, int lastFrame)
{
    const std::string path = std::string(VFIELD_SCENES_DIR) + "/" + name;
    std::ifstream in(path);
    nlohmann::json scene = nlohmann::json::parse(in);
    if (scene.contains("clouds"))
        for (auto& cloud : scene["clouds"]) cloud["count"] = particles;
    scene["frames"]["end"] = lastFrame;
    // The detail's noise at twice the voxel: an eighth of the voxels, the
    // same code (the look itself is guarded by the golden images).
    if (scene.contains("volume") && scene["volume"].contains("detail") && scene["volume"]["detail"].contains("voxelSize"))
        scene["volume"]["detail"]["voxelSize"] = 2.0 * scene["volume"]["detail"]["voxelSize"].get<double>();
    return parseScene(scene.dump(), path); // the path anchors meshes/
}

} // namespace vfield::test
