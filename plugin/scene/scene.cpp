#include <vfield/scene/scene.h>

#include <vfield/core/error.h>
#include <vfield/core/options.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace vfield {

const ObjectSpec* Scene::findObject(const std::string& name) const
{
    for (const ObjectSpec& object : simulation.objects)
        if (object.name == name) return &object;
    return nullptr;
}

void Scene::validate() const
{
    simulation.validate();
    render.validate();
    if (const auto& follow = render.camera.followObject) {
        const ObjectSpec* target = findObject(*follow);
        require(target && target->isDynamic, "camera",
                "\"follow\" names \"" + *follow + "\", which is not a dynamic object of the scene");
    }
    for (const CloudSpec& cloud : simulation.clouds) {
        const double voxel = volume.voxelSize;
        const double voxels = 8.0 * cloud.radii[0] * cloud.radii[1] * cloud.radii[2] / (voxel * voxel * voxel);
        require(voxels <= kMaxDensityVoxels, "volume",
                "cloud \"" + cloud.name + "\" would fill about " + std::to_string(uint64_t(voxels)) + " voxels of size " +
                    numberText(voxel) + " (at most 2e9): raise volume.voxelSize");
    }
    validatePart("volume", volume);
}

Scene parseScene(const std::string& text, const std::string& file)
{
    const JsonValue root = parseJson(text, file);
    const std::string baseDir = std::filesystem::path(file).parent_path().string();
    JsonObject o(root);
    Scene scene;
    scene.path = file;

    const JsonValue version = o.at("version");
    if (version.asInt() != 1) version.fail("this vfield reads scene version 1");

    SimulationSetup& sim = scene.simulation;
    if (const auto frames = o.find("frames")) {
        JsonObject f(*frames);
        sim.firstFrame = f.integer("start", sim.firstFrame);
        sim.lastFrame = f.integer("end", sim.lastFrame);
        sim.fps = f.number("fps", sim.fps);
        f.finish();
    }
    sim.seed = o.unsignedInteger("seed", sim.seed);
    for (const JsonValue& item : o.at("objects").asArray()) sim.objects.push_back(objectSpecFromJson(item, baseDir));
    if (const auto clouds = o.find("clouds"))
        for (const JsonValue& item : clouds->asArray()) sim.clouds.push_back(cloudSpecFromJson(item));
    if (const auto fields = o.find("fields"))
        for (const JsonValue& item : fields->asArray()) sim.fields.push_back(uniformFieldSpecFromJson(item));
    if (const auto options = o.find("simulation")) sim.options = simulationOptionsFromJson(*options);

    if (const auto volume = o.find("volume")) scene.volume = volumeOptionsFromJson(*volume);
    // The density's defaults follow the clouds' particles, resolved once here.
    double radii = 0.0, particles = 0.0;
    for (const CloudSpec& cloud : sim.clouds) {
        radii += cloud.particleRadius * double(cloud.count);
        particles += double(cloud.count);
    }
    if (const auto camera = o.find("camera")) scene.render.camera = cameraSettingsFromJson(*camera);
    if (const auto sun = o.find("sun")) scene.render.sun = sunSettingsFromJson(*sun);
    if (const auto sky = o.find("sky")) scene.render.sky = skySettingsFromJson(*sky);
    if (const auto render = o.find("render")) renderSectionFromJson(*render, scene.render);
    o.finish();
    validateAt(root, [&] {
        scene.simulation.validate();
        scene.volume = scene.volume.resolved(particles > 0 ? radii / particles : 1.0);
        scene.validate();
    });
    return scene;
}

Scene loadScene(const std::string& path, const std::vector<SceneOverride>& overrides)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError(path, std::filesystem::exists(path) ? "cannot open for reading" : "no such file");
    std::stringstream text;
    text << in.rdbuf();
    if (overrides.empty()) return parseScene(text.str(), path);

    nlohmann::json json = parseJson(text.str(), path).raw(); // syntax errors name the file's line and column
    for (const SceneOverride& o : overrides) {
        const std::string what = "override " + o.pointer + "=" + o.value + ": ";
        if (o.pointer.empty() || o.pointer[0] != '/') throw ValueError(what + "a JSON pointer starts with '/'");
        nlohmann::json value;
        try {
            value = parseJson(o.value, "override").raw();
        } catch (const ParseError&) {
            throw ValueError(what + "the value is not JSON (a string needs its quotes)");
        }
        try {
            json[nlohmann::json::json_pointer(o.pointer)] = value;
        } catch (const nlohmann::json::exception& e) {
            throw ValueError(what + "no such place in the scene (" + e.what() + ")");
        }
    }
    return parseScene(json.dump(2), path);
}

} // namespace vfield
