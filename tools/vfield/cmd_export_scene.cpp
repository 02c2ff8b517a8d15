// vfield export-scene SCENE --sim DIR: DIR/host/, what Blender's add-on and
// other hosts read (host.json and the meshes), written again after an edit of
// the camera, sun, sky or materials that needs no new simulation.

#include "command.h"
#include "scene_cli_options.h"

#include <vfield/core/error.h>
#include <vfield/core/folder_lock.h>
#include <vfield/folder/sim_folder.h>
#include <vfield/host/host_scene.h>

#include <filesystem>

namespace vfield::cli {

Runner registerExportScene(CLI::App& app, const GlobalOptions& global)
{
    struct Options {
        SceneCliOptions scene;
        std::string sim;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand(
        "export-scene", "Write SIM/host/host.json and the objects' meshes: the scene as a host application rebuilds it "
                        "(vfield simulate writes them too)");
    addSceneOptions(*command, o->scene);
    command->add_option("--sim", o->sim, "Simulation folder of the scene")->required();

    return [o, &global] {
        const Scene scene = loadScene(o->scene);
        if (!std::filesystem::is_directory(o->sim)) throw FileError(o->sim, "no such simulation folder");
        const FolderLock lock(o->sim, "vfield export-scene");
        const SimFolder simulation(o->sim);
        writeHostScene(scene, simulation);
        log(global, hostSceneDir(simulation) + "/host.json written");
    };
}

} // namespace vfield::cli
