// vfield export-mesh SCENE --object NAME -o mesh.obj: any object's mesh for other tools.

#include "command.h"
#include "scene_cli_options.h"

#include <vfield/core/error.h>
#include <vfield/scene/scene.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace vfield::cli {

namespace {

/// The pose of a dynamic object at a frame, from a simulation's tracks.json.
Transform poseFromTracks(const std::string& simDir, const std::string& object, int frame, double scale)
{
    const std::string path = (std::filesystem::path(simDir) / "tracks.json").string();
    std::ifstream in(path);
    if (!in) throw FileError(path, "cannot open for reading (simulate the scene first)");
    nlohmann::json tracks;
    try {
        in >> tracks;
        for (const nlohmann::json& entry : tracks.at("objects").at(object)) {
            if (entry.at("frame").get<int>() != frame) continue;
            Transform pose;
            const auto p = entry.at("position").get<std::vector<double>>();
            const auto q = entry.at("orientation").get<std::vector<double>>();
            pose.translation = Vec3d(p.at(0), p.at(1), p.at(2));
            pose.rotation = Quatd(q.at(0), q.at(1), q.at(2), q.at(3));
            pose.scale = scale;
            return pose;
        }
    } catch (const nlohmann::json::exception& e) {
        throw FileError(path, std::string("unreadable tracks: ") + e.what());
    }
    throw FileError(path, "no track of \"" + object + "\" at frame " + std::to_string(frame));
}

} // namespace

Runner registerExportMesh(CLI::App& app, const GlobalOptions& global)
{
    struct Options {
        SceneCliOptions scene;
        std::string object, output, sim;
        int frame = 0;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand(
        "export-mesh", "Write a scene object's mesh as OBJ: static objects in world space; dynamic ones in object space "
                       "(nose +x, up +y, pivot at the origin) unless --frame places them from a simulation's tracks");
    addSceneOptions(*command, o->scene);
    command->add_option("--object", o->object, "Object name")->required();
    command->add_option("--frame", o->frame, "Place a dynamic object as it is at this frame (needs --sim)");
    command->add_option("--sim", o->sim, "Simulation folder whose tracks.json places dynamic objects");
    command->add_option("-o,--output", o->output, "Output .obj file")->required();

    return [o, command, &global] {
        const Scene scene = loadScene(o->scene);
        const ObjectSpec* spec = scene.findObject(o->object);
        if (!spec) throw FileError(o->scene.path, "no object named \"" + o->object + "\"");
        TriangleMesh mesh = makeMesh(spec->mesh);
        if (!spec->isDynamic) {
            mesh.transform(spec->transform.matrix());
        } else if (command->count("--frame") > 0) {
            if (o->sim.empty()) throw ValueError("--frame places a dynamic object from a simulation: give --sim DIR");
            mesh.transform(poseFromTracks(o->sim, o->object, o->frame, spec->transform.scale).matrix());
        }
        saveObj(mesh, o->output);
        log(global, o->output + ": " + std::to_string(mesh.triangleCount()) + " triangles");
    };
}

} // namespace vfield::cli
