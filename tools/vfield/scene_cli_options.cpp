#include "scene_cli_options.h"

namespace vfield::cli {

void addSceneOptions(CLI::App& command, SceneCliOptions& options, bool sceneRequired)
{
    command.add_option("scene", options.path, "Scene file (JSON, see scenes/README.md)")->required(sceneRequired);
    command
        .add_option("--set", options.overrides,
                    "Change a scene value before reading it: JSON pointer=JSON value, e.g. --set /clouds/0/count=5000 "
                    "--set '/render/resolution=[320,180]' (repeatable)")
        ->check([](const std::string& text) {
            return text.find('=') == std::string::npos ? "expected POINTER=VALUE, got '" + text + "'" : std::string();
        });
}

Scene loadScene(const SceneCliOptions& options)
{
    std::vector<SceneOverride> overrides;
    for (const std::string& text : options.overrides) {
        const std::size_t equals = text.find('=');
        overrides.push_back({text.substr(0, equals), text.substr(equals + 1)});
    }
    Scene scene = vfield::loadScene(options.path, overrides);
    for (ObjectSpec& object : scene.simulation.objects) {
        if (!object.repulsion) continue;
        if (options.splitRule) object.repulsion->field.splitRule = *options.splitRule;
        if (options.repulsionMethod) object.repulsion->method = *options.repulsionMethod;
    }
    return scene;
}

} // namespace vfield::cli
