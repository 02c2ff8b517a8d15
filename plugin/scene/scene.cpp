#include <vfield/scene/scene.h>

#include <vfield/core/error.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace vfield {

namespace {

uint64_t hashBytes(const std::string& text)
{
    uint64_t h = 1469598103934665603ull; // FNV-1a
    for (const unsigned char c : text) h = (h ^ c) * 1099511628211ull;
    return h;
}

/// The density grid must fit: the clouds' initial boxes over the voxel size.
void checkVolumeSize(const Scene& scene, const JsonValue& where)
{
    constexpr double kMaxVoxels = 2e9;
    for (const CloudSpec& cloud : scene.simulation.clouds) {
        const double voxel = scene.volume.voxelSize > 0 ? scene.volume.voxelSize : cloud.particleRadius;
        const double voxels = 8.0 * cloud.radii[0] * cloud.radii[1] * cloud.radii[2] / (voxel * voxel * voxel);
        if (voxels > kMaxVoxels)
            where.fail("cloud \"" + cloud.name + "\" would fill about " + std::to_string(uint64_t(voxels)) + " voxels of size " +
                       std::to_string(voxel) + " (at most 2e9): raise volume.voxelSize");
    }
}

} // namespace

const ObjectSpec* Scene::findObject(const std::string& name) const
{
    for (const ObjectSpec& object : simulation.objects)
        if (object.name == name) return &object;
    return nullptr;
}

Scene parseScene(const std::string& text, const std::string& file)
{
    const JsonValue root = parseJson(text, file);
    const std::string baseDir = std::filesystem::path(file).parent_path().string();
    JsonObject o(root);
    Scene scene;
    scene.path = file;
    nlohmann::json simulated = nlohmann::json::object();
    for (const char* key : {"version", "frames", "seed", "objects", "clouds", "fields", "simulation", "volume"})
        if (root.raw().contains(key)) simulated[key] = root.raw().at(key);
    scene.simulationHash = hashBytes(simulated.dump());

    const JsonValue version = o.at("version");
    if (version.asInteger(1, INT32_MAX) != 1) version.fail("this vfield reads scene version 1");

    SimulationSetup& sim = scene.simulation;
    if (const auto frames = o.find("frames")) {
        JsonObject f(*frames);
        sim.firstFrame = int(f.integer("start", sim.firstFrame, 0, 9999));
        sim.lastFrame = int(f.integer("end", sim.lastFrame, 0, 9999));
        sim.fps = f.number("fps", sim.fps, 1e-3, 1e4);
        if (sim.lastFrame < sim.firstFrame) frames->fail("\"end\" comes before \"start\"");
        f.finish();
    }
    sim.seed = uint64_t(o.integer("seed", int64_t(sim.seed), 0, INT64_MAX));

    std::set<std::string> names;
    for (const JsonValue& item : o.at("objects").asArray()) {
        sim.objects.push_back(objectSpecFromJson(item, baseDir));
        if (!names.insert(sim.objects.back().name).second)
            item.fail("another object is already named \"" + sim.objects.back().name + "\"");
    }
    int64_t particles = 0;
    if (const auto clouds = o.find("clouds"))
        for (const JsonValue& item : clouds->asArray()) {
            sim.clouds.push_back(cloudSpecFromJson(item));
            particles += sim.clouds.back().count;
            if (particles > kMaxParticles)
                item.fail("the clouds ask for more than " + std::to_string(kMaxParticles) + " particles in all");
        }
    if (sim.clouds.size() > 65535) o.at("clouds").fail("at most 65535 clouds");
    if (const auto fields = o.find("fields"))
        for (const JsonValue& item : fields->asArray()) sim.fields.push_back(uniformFieldSpecFromJson(item));
    if (const auto options = o.find("simulation")) sim.options = simulationOptionsFromJson(*options);

    if (const auto volume = o.find("volume")) scene.volume = volumeOptionsFromJson(*volume);
    if (const auto camera = o.find("camera")) {
        scene.render.camera = cameraSettingsFromJson(*camera);
        const auto& follow = scene.render.camera.followObject;
        if (follow) {
            const ObjectSpec* target = scene.findObject(*follow);
            if (!target || !target->isDynamic)
                camera->fail("\"follow\" names \"" + *follow + "\", which is not a dynamic object of the scene");
        }
    }
    if (const auto sun = o.find("sun")) scene.render.sun = sunSettingsFromJson(*sun);
    if (const auto sky = o.find("sky")) scene.render.sky = skySettingsFromJson(*sky);
    if (const auto render = o.find("render")) scene.render.image = imageSettingsFromJson(*render);
    o.finish();
    checkVolumeSize(scene, root);
    return scene;
}

Scene loadScene(const std::string& path, const std::vector<SceneOverride>& overrides)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError(path, std::filesystem::exists(path) ? "cannot open for reading" : "no such file");
    std::stringstream text;
    text << in.rdbuf();
    if (overrides.empty()) return parseScene(text.str(), path);

    parseJson(text.str(), path); // syntax errors name the file's line and column
    nlohmann::json json = nlohmann::json::parse(text.str());
    for (const SceneOverride& o : overrides) {
        const std::string what = "override " + o.pointer + "=" + o.value + ": ";
        if (o.pointer.empty() || o.pointer[0] != '/') throw ValueError(what + "a JSON pointer starts with '/'");
        nlohmann::json value;
        try {
            value = nlohmann::json::parse(o.value);
        } catch (const nlohmann::json::exception&) {
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
