#include "scene_cli_options.h"

#include <vfield/field/repulsion_field.h>
#include <vfield/render/render_settings.h>

#include <nlohmann/json.hpp>

namespace vfield::cli {

namespace {

/// "a|b|c" of an enum's names, for help text.
template<typename Enum>
std::string nameChoices()
{
    std::string text;
    for (const std::string& name : enumNameList<Enum>()) text += (text.empty() ? "" : "|") + name;
    return text;
}

/// --flag NAME, a shorthand for --set POINTER="NAME", NAME one of the enum's.
template<typename Enum>
void addEnumShorthand(CLI::App& command, SceneCliOptions& options, const std::string& flag, const std::string& pointer,
                      const std::string& help)
{
    command
        .add_option_function<std::string>(
            flag,
            [&options, pointer](const std::string& name) {
                options.shorthands.push_back(pointer + "=" + nlohmann::json(name).dump());
            },
            help + " (--set " + pointer + "=\"NAME\") [default: the scene's]")
        ->check(CLI::IsMember(enumNameList<Enum>()).description(""))
        ->type_name(nameChoices<Enum>());
}

} // namespace

std::vector<std::string> SceneCliOptions::allOverrides() const
{
    std::vector<std::string> all = overrides;
    all.insert(all.end(), shorthands.begin(), shorthands.end());
    return all;
}

void addSceneOptions(CLI::App& command, SceneCliOptions& options, bool sceneRequired)
{
    command.add_option("scene", options.path, "Scene file (JSON, see docs/scenes.md)")->required(sceneRequired);
    command
        .add_option("--set", options.overrides,
                    "Change a scene value before reading it: JSON pointer=JSON value, e.g. --set /clouds/0/count=5000 "
                    "--set '/render/resolution=[320,180]'; * stands for every element of an array (repeatable)")
        ->check([](const std::string& text) {
            return text.find('=') == std::string::npos ? "expected POINTER=VALUE, got '" + text + "'" : std::string();
        });
}

void addRepulsionShorthands(CLI::App& command, SceneCliOptions& options)
{
    addEnumShorthand<RepulsionMethod>(command, options, "--repulsion-method", "/objects/*/repulsion/method",
                                      "How every object's repulsive field is made: octree (the paper's), distance (from "
                                      "the signed distance) or potentialFlow (the clouds' wind flowing around static objects)");
    addEnumShorthand<SplitRule>(command, options, "--split-rule", "/objects/*/repulsion/splitRule",
                                "When every object's octree node is split: normalCone (also while two of its triangles "
                                "face more than 90 degrees apart) or paper (the triangle count only)");
}

void addRenderShorthands(CLI::App& command, SceneCliOptions& options)
{
    command
        .add_option_function<std::string>(
            "--resolution",
            [&options](const std::string& text) {
                const std::size_t x = text.find('x');
                const auto whole = [](const std::string& digits) {
                    return !digits.empty() && digits.size() < 10 && digits.find_first_not_of("0123456789") == std::string::npos;
                };
                if (x == std::string::npos || !whole(text.substr(0, x)) || !whole(text.substr(x + 1)))
                    throw CLI::ValidationError("--resolution", "expected WxH, e.g. 1280x720, got '" + text + "'");
                options.shorthands.push_back("/render/resolution=[" + text.substr(0, x) + "," + text.substr(x + 1) + "]");
            },
            "Image size WxH (--set /render/resolution=[W,H]) [default: the scene's]")
        ->type_name("WxH");
    command
        .add_option_function<int>(
            "--spp", [&options](int spp) { options.shorthands.push_back("/render/samplesPerPixel=" + std::to_string(spp)); },
            "Samples per pixel (--set /render/samplesPerPixel=N) [default: the scene's]")
        ->type_name("N");
    command.add_flag_callback(
        "--transparent-sky", [&options] { options.shorthands.push_back("/render/transparentSky=true"); },
        "Draw the sky as RGB 0, alpha 0 (premultiplied), to composite over a plate (--set /render/transparentSky=true) "
        "[default: the scene's]");
    command
        .add_option_function<std::string>(
            "--view",
            [&options](const std::string& name) { options.shorthands.push_back("/render/view=" + nlohmann::json(name).dump()); },
            "The OpenColorIO view PNG frames show: Filmic, Standard, Raw, or one of $OCIO's config (--set "
            "/render/view=\"NAME\") [default: the scene's]")
        ->type_name("NAME");
    command
        .add_option_function<double>(
            "--exposure",
            [&options](double stops) { options.shorthands.push_back("/render/exposure=" + nlohmann::json(stops).dump()); },
            "Stops of exposure before the view; EXR frames keep the light as rendered (--set /render/exposure=STOPS) "
            "[default: the scene's]")
        ->type_name("STOPS");
    addEnumShorthand<IntegratorKind>(
        command, options, "--integrator", "/render/integrator",
        "vfield's renderer: fast (ray march, light grids, multiple scattering by octaves or by paths) or "
        "reference (an unbiased path tracer, slow and noisy: give it many --spp)");
}

void addPovrayShorthands(CLI::App& command, SceneCliOptions& options)
{
    command.add_flag_callback(
        "--keep-scene", [&options] { options.shorthands.push_back("/povray/keepScene=true"); },
        "Keep POV-Ray's .pov, .inc and .df3 files in OUT/povray-scene/ (--set /povray/keepScene=true)");
    command
        .add_option_function<int>(
            "--povray-threads",
            [&options](int threads) { options.shorthands.push_back("/povray/threads=" + std::to_string(threads)); },
            "POV-Ray's render threads; 1 makes its media noise reproducible (--set /povray/threads=N) [default: as "
            "--threads]")
        ->check(CLI::PositiveNumber)
        ->type_name("N");
}

Scene loadScene(const SceneCliOptions& options)
{
    std::vector<SceneOverride> overrides;
    for (const std::string& text : options.allOverrides()) {
        const std::size_t equals = text.find('=');
        overrides.push_back({text.substr(0, equals), text.substr(equals + 1)});
    }
    return vfield::loadScene(options.path, overrides);
}

} // namespace vfield::cli
