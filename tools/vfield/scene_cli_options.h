#pragma once
// The scene argument that simulate, render, run and export-mesh share, with
// --set overrides of its values.

#include "command.h"

#include <vfield/scene/scene.h>

#include <optional>
#include <string>
#include <vector>

namespace vfield::cli {

struct SceneCliOptions {
    std::string path;
    std::vector<std::string> overrides;             ///< "POINTER=JSON", in order
    std::optional<SplitRule> splitRule;             ///< for every object's field (--split-rule, simulate and run)
    std::optional<RepulsionMethod> repulsionMethod; ///< for every object's field (--repulsion-method, simulate and run)
};

/// Declares SCENE (required unless told otherwise: `farm status` takes none) and --set.
void addSceneOptions(CLI::App& command, SceneCliOptions& options, bool sceneRequired = true);

/// Loads the scene with its overrides applied.
Scene loadScene(const SceneCliOptions& options);

} // namespace vfield::cli
