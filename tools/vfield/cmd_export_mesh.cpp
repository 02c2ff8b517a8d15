// vfield export-mesh SCENE --object NAME -o mesh.obj: any object's mesh for other tools.

#include "command.h"
#include "scene_cli_options.h"

#include <vfield/core/error.h>
#include <vfield/folder/sim_folder.h>
#include <vfield/scene/scene.h>

namespace vfield::cli {

Runner registerExportMesh(CLI::App& app, const GlobalOptions& global)
{
    struct Options {
        SceneCliOptions scene;
        std::string object, output, sim;
        int frame = 0;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand(
        "export-mesh",
        "Write a scene object's mesh as OBJ. Static objects: world space (the scene's transform applied). Dynamic "
        "objects: object space, unscaled (nose +x, up +y, pivot at the origin; tracks.json's per-frame transform, its "
        "scale included, places it), or world space at --frame from a simulation's tracks.json");
    addSceneOptions(*command, o->scene);
    command->add_option("--object", o->object, "Object name")->required();
    command->add_option("--frame", o->frame, "Place a dynamic object as it is at this frame (needs --sim)");
    command->add_option("--sim", o->sim, "Simulation folder whose tracks.json places dynamic objects");
    command->add_option("-o,--output", o->output, "Output .obj file")->required();

    return [o, command, &global] {
        const Scene scene = loadScene(o->scene);
        const ObjectSettings* spec = scene.findObject(o->object);
        if (!spec) throw FileError(o->scene.path, "no object named \"" + o->object + "\"");
        TriangleMesh mesh = makeMesh(spec->mesh);
        if (!spec->isDynamic) {
            mesh.transform(spec->transform.matrix());
        } else if (command->count("--frame") > 0) {
            if (o->sim.empty()) throw ValueError("--frame places a dynamic object from a simulation: give --sim DIR");
            mesh.transform(SimFolder(o->sim).readTracks().pose(o->object, o->frame).matrix());
        }
        saveObj(mesh, o->output);
        log(global, o->output + ": " + std::to_string(mesh.triangleCount()) + " triangles");
    };
}

} // namespace vfield::cli
