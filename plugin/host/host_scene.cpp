#include <vfield/host/host_scene.h>

#include "../core/json_vec3.h"

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>
#include <vfield/core/field_visitors.h>
#include <vfield/folder/sim_folder.h>
#include <vfield/mesh/mesh_io.h>
#include <vfield/render/camera.h>
#include <vfield/render/embree/surfaces.h>
#include <vfield/render/materials.h>

#include <nlohmann/json.hpp>

#include <cctype>
#include <filesystem>
#include <optional>

namespace fs = std::filesystem;

namespace vfield {

namespace {

/// "12-red_wing.obj": the index keeps names apart that differ only in
/// characters a file name should not hold.
std::string meshFileName(std::size_t index, const std::string& name)
{
    std::string safe;
    for (const char c : name) safe += std::isalnum(static_cast<unsigned char>(c)) || c == '-' ? c : '_';
    return std::to_string(index) + "-" + safe + ".obj";
}

nlohmann::json cameraPose(int frame, const Camera& camera, double fovDegrees)
{
    return {{"frame", frame},
            {"position", vec3ToJson(camera.position())},
            {"lookAt", vec3ToJson(camera.position() + camera.forward())},
            {"up", vec3ToJson(camera.up())},
            {"fovDegrees", fovDegrees}};
}

/// One pose for a fixed camera; one per frame for a camera that moves by
/// itself (keys, a path) or follows an object, placed as the renderer places
/// it (in front of any surface between it and the object).
nlohmann::json cameraPoses(const Scene& scene, const std::vector<TriangleMesh>& meshes, const SimFolder& simulation, int first,
                           int last)
{
    const RenderSettings& settings = scene.render;
    const int width = settings.image.width, height = settings.image.height;
    nlohmann::json poses = nlohmann::json::array();
    if (!settings.camera.follow) {
        for (int f = first; f <= (settings.camera.moves() ? last : first); ++f) {
            const CameraSettings camera = settings.camera.at(f);
            poses.push_back(cameraPose(f, Camera::fromSettings(camera, width, height), camera.fovDegrees));
        }
        return poses;
    }
    SurfaceScene surfaces;
    int followed = -1;
    const std::vector<ObjectSettings>& objects = scene.simulation.objects;
    for (std::size_t i = 0; i < objects.size(); ++i) {
        if (objects[i].isDynamic) {
            surfaces.addDynamic(int(i), meshes[i]);
            if (objects[i].name == settings.camera.follow->object) followed = int(i);
        } else {
            surfaces.addStatic(int(i), meshes[i], objects[i].transform);
        }
    }
    const Tracks tracks = simulation.readTracks();
    const FirstSurfaceQuery firstSurface = [&surfaces](const Vec3d& origin, const Vec3d& dir, double tMin, double tMax) {
        SurfaceHit hit;
        return surfaces.intersect(origin, dir, tMin, tMax, hit) ? std::optional<double>(hit.distance) : std::nullopt;
    };
    for (int f = first; f <= last; ++f) {
        for (std::size_t i = 0; i < objects.size(); ++i)
            if (objects[i].isDynamic) surfaces.setPose(int(i), tracks.pose(objects[i].name, f));
        surfaces.commit();
        const std::vector<Transform> path = tracks.path(objects[std::size_t(followed)].name, f);
        const CameraSettings camera = settings.camera.at(f);
        poses.push_back(cameraPose(f, followCamera(camera, path, firstSurface, width, height), camera.fovDegrees));
    }
    return poses;
}

/// The sun at frame f: its direction (a unit vector), colour and intensity.
nlohmann::json sunAt(const RenderSettings& settings, int f)
{
    const SunSettings sun = atFrame(settings.sun, f);
    return {{"frame", f},
            {"direction", vec3ToJson(sun.direction.unitSafe())},
            {"color", vec3ToJson(sun.color)},
            {"intensity", sun.intensity}};
}

} // namespace

std::string hostSceneDir(const SimFolder& simulation) { return (fs::path(simulation.path()) / "host").string(); }

void writeHostScene(const Scene& scene, const SimFolder& simulation)
{
    const StatsFile stats = simulation.readStats();
    if (stats.frames.empty()) throw FileError(simulation.statsFile(), "no finished frame to describe");
    const int first = stats.frames.front().frame, last = stats.frames.back().frame;
    const fs::path dir = hostSceneDir(simulation);
    fs::create_directories(dir);

    bool anyDynamic = false;
    std::vector<TriangleMesh> meshes;
    nlohmann::json objects = nlohmann::json::array();
    for (std::size_t i = 0; i < scene.simulation.objects.size(); ++i) {
        const ObjectSettings& object = scene.simulation.objects[i];
        meshes.push_back(makeMesh(object.mesh));
        TriangleMesh placed = meshes.back();
        if (!object.isDynamic) placed.transform(object.transform.matrix());
        anyDynamic = anyDynamic || object.isDynamic;
        const std::string file = meshFileName(i, object.name);
        saveObj(placed, (dir / file).string());
        const SurfaceMaterial material = surfaceMaterialOf(object);
        objects.push_back({{"name", object.name},
                           {"mesh", file},
                           {"space", object.isDynamic ? "object" : "world"},
                           {"material",
                            {{"kind", material.kind == SurfaceMaterial::Kind::Terrain ? "terrain" : "painted"},
                             {"color", vec3ToJson(material.paint)}}}});
    }

    const RenderSettings& r = scene.render;
    nlohmann::json camera = {{"fovDegrees", r.camera.fovDegrees},
                             {"resolution", {r.image.width, r.image.height}},
                             {"follows", r.camera.follow ? nlohmann::json(r.camera.follow->object) : nullptr},
                             {"poses", cameraPoses(scene, meshes, simulation, first, last)}};
    nlohmann::json volume = {{"files", "../density.####.vdb"},
                             {"densityGrid", "density"},
                             {"velocityGrid", "vel"},
                             {"velocityUnit", "world units per second"}};
    volume.update(fieldsToJson(r.medium));
    nlohmann::json sun = sunAt(r, first);
    if (!r.sun.animation.empty()) {
        sun["frames"] = nlohmann::json::array();
        for (int f = first; f <= last; ++f) sun["frames"].push_back(sunAt(r, f));
    }
    const nlohmann::json host = {{"format", "vfield host scene"},
                                 {"version", 1},
                                 {"convention", "y up, right-handed, world units; paths relative to this file"},
                                 {"scene", fs::absolute(scene.path).lexically_normal().string()},
                                 {"fps", stats.fps},
                                 {"frames", {first, last}},
                                 {"volume", volume},
                                 {"tracks", anyDynamic ? nlohmann::json("../tracks.json") : nullptr},
                                 {"objects", objects},
                                 {"camera", camera},
                                 {"sun", sun},
                                 {"sky", fieldsToJson(atFrame(r.sky, first))}};
    writeTextAtomically((dir / "host.json").string(), host.dump(1) + "\n");
}

} // namespace vfield
