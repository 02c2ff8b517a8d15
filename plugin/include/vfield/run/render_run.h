#pragma once
/// @file render_run.h
/// Scene + a simulation folder -> image files, one set per frame, through a
/// back-end picked by name (render_backends.h: embree, povray or both).
/// Reads each frame's density and the dynamic objects' tracks through
/// SimFolder, refusing a frame that the folder's simulation did not make
/// (its inputs hash, stats.json's, differs); places the dynamic objects and the camera, lights the cloud,
/// and hands the frame to the back-end. Frames rendered before with the same
/// settings whose images are newer than their simulation are skipped unless
/// forced (OUT/render-stamps.json records each frame's settings). One run
/// writes an output folder at a time (FolderLock).
/// Every back-end reads the scene's render settings and nothing else: to
/// change the image size or samples, change the scene (Scene::render.image),
/// as the command line's --resolution and --spp do.

#include <vfield/core/folder_lock.h>
#include <vfield/render/materials.h>
#include <vfield/scene/scene.h>

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace vfield {

struct RenderRunOptions {
    std::string backend = "embree";           ///< renderBackendNames()
    std::optional<int> firstFrame, lastFrame; ///< default: the scene's range
    std::vector<std::string> formats{"png"};  ///< "png" and/or "exr"
    bool force = false;                       ///< re-render frames whose images exist
    std::function<void(int frame, int done, int total, double seconds)> progress;
    /// Told, while a frame is rendered, its number, the frames done and to do
    /// (as progress) and the fraction of its pixels done (0 while the renderer
    /// and the frame's light are prepared), about once a second, one call at a
    /// time (from worker threads).
    std::function<void(int frame, int done, int total, double fraction)> frameProgress;
    /// Called once per thing the scene asks that the back-end cannot draw,
    /// before the first frame.
    std::function<void(const std::string& line)> warning;
    /// The output folder has one writer at a time (FolderLock). When another
    /// process writes it, this is called with who, and the run waits for it;
    /// unset: the run is refused at once.
    FolderLock::Waiting waitForFolder;
    /// Called with each frame before its files are first read (the first
    /// frame's also before stats.json is), returning once the simulation
    /// folder holds it: how runScene follows a simulation as it is written.
    /// Unset: the folder is complete.
    std::function<void(int frame)> waitForFrame;
};

struct RenderRunSummary {
    int rendered = 0, skipped = 0;
    double secondsPerFrame = 0.0; ///< mean over rendered frames, everything included
    /// Mean seconds a rendered frame spent in each back-end (a composite's parts each).
    std::map<std::string, double> backendSecondsPerFrame;
};

RenderRunSummary renderScene(const Scene& scene, const std::string& simulationDir, const std::string& outputDir,
                             const RenderRunOptions& options = {});

} // namespace vfield
