#pragma once
/// @file render_run.h
/// Scene + a simulation folder -> OUT/frame.####.png (and/or .exr), one per
/// frame, through vfield's Embree back-end. Reads density.####.vdb and
/// tracks.json from the simulation; writes every image atomically; frames
/// whose images exist are skipped unless forced.

#include <vfield/scene/scene.h>

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace vfield {

struct RenderRunOptions {
    std::optional<int> firstFrame, lastFrame; ///< default: the scene's range
    std::optional<int> width, height;         ///< default: the scene's resolution
    std::optional<int> samplesPerPixel;       ///< default: the scene's
    std::vector<std::string> formats{"png"};  ///< "png" and/or "exr"
    bool force = false;                       ///< re-render frames whose images exist
    std::function<void(int frame, int done, int total, double seconds)> progress;
};

struct RenderRunSummary {
    int rendered = 0, skipped = 0;
    double secondsPerFrame = 0.0; ///< mean over rendered frames
};

RenderRunSummary renderScene(const Scene& scene, const std::string& simulationDir, const std::string& outputDir,
                             const RenderRunOptions& options = {});

} // namespace vfield
