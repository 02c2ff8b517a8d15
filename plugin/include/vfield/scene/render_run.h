#pragma once
/// @file render_run.h
/// Scene + a simulation folder -> OUT/frame.####.png (and/or .exr), one per
/// frame, through vfield's Embree back-end, POV-Ray, or both. Reads each
/// frame's density and the dynamic objects' tracks through SimFolder; writes
/// every image atomically; frames whose images exist are skipped unless forced.
/// Every back-end reads the scene's render settings and nothing else: to
/// change the image size or samples, change a copy of the scene
/// (Scene::render.image), as the command line's --resolution and --spp do.
///
/// Outputs per back-end:
///   embree: OUT/frame.####.png (and/or .exr)
///   povray: OUT/frame.####.png; its scene files are written to
///           OUT/povray-scene/ (meshes.inc, frame.####.pov, density.####.df3)
///           and removed after each frame unless kept
///   both:   OUT/embree/frame.####.*, OUT/povray/frame.####.png and
///           OUT/frame.####.png, the two side by side (Embree on the left)

#include <vfield/render/materials.h>
#include <vfield/scene/scene.h>

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace vfield {

enum class RenderBackend { Embree, Povray, Both };

struct RenderRunOptions {
    RenderBackend backend = RenderBackend::Embree;
    std::optional<int> firstFrame, lastFrame; ///< default: the scene's range
    std::vector<std::string> formats{"png"};  ///< "png" and/or "exr"
    bool force = false;                       ///< re-render frames whose images exist
    bool keepScene = false;                   ///< keep POV-Ray's scene files in OUT/povray-scene/
    /// POV-Ray's render threads; its media sampling is reproducible with 1
    /// only. Default: as many as vfield's (tbb's task arena).
    std::optional<int> povrayThreads;
    std::function<void(int frame, int done, int total, double seconds)> progress;
};

struct RenderRunSummary {
    int rendered = 0, skipped = 0;
    double secondsPerFrame = 0.0;       ///< mean over rendered frames, everything included
    double embreeSecondsPerFrame = 0.0; ///< mean time in vfield's renderer (0 if unused)
    double povraySecondsPerFrame = 0.0; ///< mean time exporting and running POV-Ray (0 if unused)
};

/// How a scene object's surface is coloured: terrain and heightmap meshes as
/// terrain, everything else painted in the object's colour.
SurfaceMaterial surfaceMaterialOf(const ObjectSpec& object);

RenderRunSummary renderScene(const Scene& scene, const std::string& simulationDir, const std::string& outputDir,
                             const RenderRunOptions& options = {});

} // namespace vfield
