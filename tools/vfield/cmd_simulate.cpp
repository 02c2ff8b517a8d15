// vfield simulate SCENE -o DIR: the scene's animation as OpenVDB volumes and
// particles per frame, with tracks and statistics, and what a host needs to
// rebuild the scene (host/).

#include "cli_values.h"
#include "command.h"
#include "progress.h"
#include "scene_cli_options.h"

#include <vfield/folder/sim_folder.h>
#include <vfield/host/host_scene.h>
#include <vfield/run/shard_merge.h>
#include <vfield/run/simulation_run.h>

#include <cstdio>
#include <memory>

namespace vfield::cli {

namespace {

std::string describe(const ClearanceStats& c)
{
    if (c.samples == 0) return "nothing measured";
    char text[160];
    std::snprintf(text, sizeof text, "min %.4g, 1st percentile %.4g, %llu penetrations in %llu samples", c.minimum, c.percentile1,
                  static_cast<unsigned long long>(c.penetrations), static_cast<unsigned long long>(c.samples));
    return text;
}

} // namespace

Runner registerSimulate(CLI::App& app, const GlobalOptions& global)
{
    struct Options {
        SceneCliOptions scene;
        std::string output;
        std::optional<FrameRange> frames;
        int threads = 0;
        std::optional<double> maxMemory;
        bool wait = false;
        std::string shard;
        int merge = 0;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand("simulate", "Animate a scene and write OpenVDB volumes and particles per frame");
    addSceneOptions(*command, o->scene);
    addRepulsionShorthands(*command, o->scene);
    command->add_option("-o,--output", o->output, "Output folder (resumes a run of the same scene found there)")->required();
    addFrameRangeOption(*command, o->frames, "Frames to write, A-B or A [default: the scene's range]");
    command->add_option("--threads", o->threads, "Worker threads [default: all cores]")->check(CLI::PositiveNumber);
    addMaxMemoryOption(*command, o->maxMemory);
    addWaitOption(*command, o->wait);
    CLI::Option* shard = command->add_option(
        "--shard", o->shard,
        "One part of a sharded simulation, into OUT/shards/: objects (the dynamic objects alone, first), or I/K (the "
        "particles whose id % K is I, the objects replayed)");
    command->add_option("--merge", o->merge, "Merge the K shards in OUT/shards/ into OUT, frame by frame")
        ->check(CLI::PositiveNumber)
        ->excludes(shard);

    return [o, &global] {
        const auto threads = limitThreads(o->threads);
        const Scene scene = loadScene(o->scene);
        SimulateOptions options;
        options.maxMemoryBytes = o->maxMemory;
        options.waitForFolder = folderWaiting(o->wait, global, o->output);
        if (o->frames) {
            options.firstFrame = o->frames->first;
            options.lastFrame = o->frames->last;
        }
        if (!o->shard.empty()) options.part = ShardPart::parse(o->shard);
        ProgressLine progress(global.quiet);
        showSimulationProgress(options, progress, o->merge > 0 ? "merged frame" : "frame");
        const SimulateSummary summary =
            o->merge > 0 ? mergeShards(scene, o->output, o->merge, options) : simulateScene(scene, o->output, options);
        for (const std::string& warning : summary.warnings) log(global, "warning: " + warning);
        if (summary.restartedStale)
            log(global, o->output + " held a simulation of an earlier edit of the scene or its meshes: simulated afresh");
        if (summary.resimulatedFrom >= 0)
            log(global, "frame " + std::to_string(summary.resimulatedFrom) + " was not as written (" +
                            summary.resimulatedBecause + "): simulated again from there");
        if (summary.resumedAfterFrame >= 0) log(global, "resumed after frame " + std::to_string(summary.resumedAfterFrame));
        log(global, "clearance of particles: " + describe(summary.worstParticles));
        for (const PairClearance& pair : summary.closestPairs) {
            char text[64];
            std::snprintf(text, sizeof text, "%.4g", pair.minimum);
            log(global, "clearance of " + pair.first + " and " + pair.second + ", mesh to mesh: " +
                            (pair.exact ? "min " : "at least ") + text + (pair.minimum < 0.0 ? " (they overlap)" : ""));
        }
        if (summary.contacts > 0)
            log(global, std::to_string(summary.contacts) +
                            " particle substeps ended on an object's surface (contacts: its field alone did not turn them away)");
        if (summary.endedInside > 0)
            log(global, "warning: " + std::to_string(summary.endedInside) + " particle substeps ended inside a dynamic object");
        const StageSeconds& s = summary.stages;
        char stages[200];
        std::snprintf(stages, sizeof stages,
                      "seconds: advection %.1f, clearance %.1f, splat %.1f, detail %.1f, write %.1f (stats.json: per frame)",
                      s.advection, s.clearance, s.splat, s.detail, s.write);
        log(global, stages);
    };
}

} // namespace vfield::cli
