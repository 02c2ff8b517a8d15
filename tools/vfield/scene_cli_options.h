#pragma once
// The scene argument that simulate, render, run, export-mesh and farm share,
// with --set overrides of its values, and the shorthands for the overrides
// users make most (--resolution, --spp, --repulsion-method, ...): each is a
// --set of a documented JSON pointer, applied before the scene is read and
// checked with everything else.

#include "command.h"

#include <vfield/scene/scene.h>

#include <string>
#include <vector>

namespace vfield::cli {

struct SceneCliOptions {
    std::string path;
    std::vector<std::string> overrides;  ///< --set "POINTER=JSON", in order
    std::vector<std::string> shorthands; ///< the shorthands' "POINTER=JSON", applied after --set

    /// --set's overrides, then the shorthands'.
    std::vector<std::string> allOverrides() const;
};

/// Declares SCENE (required unless told otherwise: `farm status` takes none) and --set.
void addSceneOptions(CLI::App& command, SceneCliOptions& options, bool sceneRequired = true);

/// --repulsion-method M and --split-rule R, for every object that has a
/// field: /objects/*/repulsion/method and .../splitRule.
void addRepulsionShorthands(CLI::App& command, SceneCliOptions& options);

/// --resolution WxH, --spp N, --transparent-sky and --integrator K:
/// /render/resolution, /render/samplesPerPixel, /render/transparentSky and
/// /render/integrator.
void addRenderShorthands(CLI::App& command, SceneCliOptions& options);

/// --keep-scene and --povray-threads N, the POV-Ray back-end's own settings:
/// /povray/keepScene and /povray/threads.
void addPovrayShorthands(CLI::App& command, SceneCliOptions& options);

/// Loads the scene with its overrides applied.
Scene loadScene(const SceneCliOptions& options);

} // namespace vfield::cli
