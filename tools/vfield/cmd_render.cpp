// vfield render SCENE --sim DIR -o OUT: image sequences of a simulated scene.

#include "cli_values.h"
#include "command.h"
#include "progress.h"
#include "scene_cli_options.h"

#include <vfield/core/error.h>
#include <vfield/folder/sim_folder.h>
#include <vfield/host/host_scene.h>
#include <vfield/run/render_backends.h>
#include <vfield/run/render_run.h>
#include <vfield/run/scene_run.h>
#include <vfield/run/simulation_run.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <sstream>

namespace vfield::cli {

namespace {

struct RenderCliOptions {
    std::optional<FrameRange> frames;
    std::string formats = "png", backend = "embree";
    int threads = 0;
    bool force = false, wait = false;
};

void addRenderOptions(CLI::App& command, RenderCliOptions& o, SceneCliOptions& scene)
{
    addFrameRangeOption(command, o.frames, "Frames to render, A-B or A [default: the scene's range]");
    command
        .add_option("--backend", o.backend,
                    "Renderer: embree (vfield's own), povray (POV-Ray 3.7), or both (adds OUT/embree/, OUT/povray/ and "
                    "side-by-side images)")
        ->check(CLI::IsMember(renderBackendNames()))
        ->capture_default_str();
    addRenderShorthands(command, scene);
    addPovrayShorthands(command, scene);
    command
        .add_option("--format", o.formats,
                    "Image files: png (8-bit, through the view), exr (scene-linear, with depth and the passes) or both")
        ->type_name("png|exr|png,exr")
        ->check(CLI::IsMember({"png", "exr", "png,exr", "exr,png"}).description(""))
        ->capture_default_str();
    command.add_option("--threads", o.threads, "Worker threads [default: all cores]")->check(CLI::PositiveNumber);
    command.add_flag("--force", o.force, "Render frames whose images exist");
    addWaitOption(command, o.wait);
}

RenderRunOptions toRunOptions(const RenderCliOptions& o)
{
    RenderRunOptions options;
    if (o.frames) {
        options.firstFrame = o.frames->first;
        options.lastFrame = o.frames->last;
    }
    options.formats.clear();
    std::istringstream list(o.formats);
    for (std::string format; std::getline(list, format, ',');) options.formats.push_back(format);
    options.force = o.force;
    options.backend = o.backend;
    return options;
}

/// The render's warnings logged, and its output folder waited for when --wait asks.
void logWarningsAndWaitForFolder(RenderRunOptions& options, bool waitForFolders, const GlobalOptions& global,
                                 const std::string& output)
{
    options.warning = [&global](const std::string& line) { log(global, "warning: " + line); };
    options.waitForFolder = folderWaiting(waitForFolders, global, output);
}

void reportRendered(const RenderRunSummary& summary, const GlobalOptions& global)
{
    char line[240];
    std::snprintf(line, sizeof line, "rendered %d frames (%.3f s each), skipped %d already complete", summary.rendered,
                  summary.secondsPerFrame, summary.skipped);
    log(global, line);
    if (summary.backendSecondsPerFrame.size() > 1) {
        std::string parts;
        for (const auto& [name, seconds] : summary.backendSecondsPerFrame) {
            std::snprintf(line, sizeof line, "%s %.3f", name.c_str(), seconds);
            parts += (parts.empty() ? "" : ", ") + std::string(line);
        }
        if (summary.backendSecondsPerFrame.size() == 2) {
            const auto& a = *summary.backendSecondsPerFrame.begin();
            const auto& b = *summary.backendSecondsPerFrame.rbegin();
            std::snprintf(line, sizeof line, " (%s / %s = %.1f)", b.first.c_str(), a.first.c_str(),
                          b.second / std::max(1e-9, a.second));
            parts += line;
        }
        log(global, "seconds per frame: " + parts);
    }
}

void renderWithProgress(const Scene& scene, const std::string& simDir, const std::string& output, RenderRunOptions options,
                        bool waitForFolders, const GlobalOptions& global)
{
    logWarningsAndWaitForFolder(options, waitForFolders, global, output);
    ProgressLine progress(global.quiet);
    options.progress = [&progress](int frame, int done, int total, double seconds) {
        progress.update(done, total, seconds, "(rendered frame " + std::to_string(frame) + ")");
    };
    const Stopwatch watch;
    options.frameProgress = [&progress, &watch](int frame, int done, int total, double fraction) {
        progress.update(done + fraction, total, watch.seconds(), "(" + renderingFrame(frame, fraction) + ")");
    };
    reportRendered(renderScene(scene, simDir, output, options), global);
}

} // namespace

Runner registerRender(CLI::App& app, const GlobalOptions& global)
{
    struct Options {
        SceneCliOptions scene;
        std::string sim, output;
        RenderCliOptions render;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand("render", "Render a simulated scene to OUT/frame.####.png (or .exr)");
    addSceneOptions(*command, o->scene);
    command->add_option("--sim", o->sim, "Simulation folder (from vfield simulate)")->required();
    command->add_option("-o,--output", o->output, "Output folder")->required();
    addRenderOptions(*command, o->render, o->scene);

    return [o, command, &global] {
        const auto threads = limitThreads(o->render.threads);
        renderWithProgress(loadScene(o->scene), o->sim, o->output, toRunOptions(o->render), o->render.wait, global);
    };
}

Runner registerRun(CLI::App& app, const GlobalOptions& global)
{
    struct Options {
        SceneCliOptions scene;
        std::string output;
        RenderCliOptions render;
        std::optional<double> maxMemory;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand(
        "run", "Simulate and render a scene: OUT/sim/ (volumes, particles, tracks, stats) and OUT/frame.####.png");
    addSceneOptions(*command, o->scene);
    addRepulsionShorthands(*command, o->scene);
    command->add_option("-o,--output", o->output, "Output folder")->required();
    addRenderOptions(*command, o->render, o->scene);
    addMaxMemoryOption(*command, o->maxMemory);

    return [o, command, &global] {
        const auto threads = limitThreads(o->render.threads);
        const Scene scene = loadScene(o->scene);
        RenderRunOptions render = toRunOptions(o->render);
        logWarningsAndWaitForFolder(render, o->render.wait, global, o->output);
        SimulateOptions simulate;
        simulate.maxMemoryBytes = o->maxMemory;
        simulate.firstFrame = render.firstFrame;
        simulate.lastFrame = render.lastFrame;
        simulate.waitForFolder = folderWaiting(o->render.wait, global, o->output + "/sim");

        RunProgress progress(global.quiet, render.lastFrame.value_or(scene.simulation.lastFrame) -
                                               render.firstFrame.value_or(scene.simulation.firstFrame) + 1);
        progress.attach(simulate, render);
        const SceneRunSummary summary = runScene(scene, o->output, simulate, render);
        if (summary.simulation.resimulatedFrom >= 0)
            log(global, "frame " + std::to_string(summary.simulation.resimulatedFrom) + " was not as written (" +
                            summary.simulation.resimulatedBecause + "): simulated again from there");
        reportRendered(summary.render, global);
    };
}

} // namespace vfield::cli
