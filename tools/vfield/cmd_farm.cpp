// vfield farm SCENE -o OUT: the scene's simulation, rendering (in chunks of
// frames) and contact sheet as batch jobs on a Slurm cluster, or one after
// another here (--engine local); --wedge runs a variant per combination of
// values. vfield farm status OUT: what is done and what is queued.

#include "cli_values.h"
#include "command.h"
#include "farm_jobs.h"
#include "progress.h"
#include "scene_cli_options.h"

#include <vfield/core/error.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace vfield::cli {

Runner registerFarm(CLI::App& app, const GlobalOptions& global)
{
    struct Options {
        SceneCliOptions scene;
        std::string output, engine = "slurm", backend = "embree", partition, account, time = "04:00:00";
        std::optional<FrameRange> frames;
        int chunk = 10, cpusPerTask = 2, shards = 0;
        bool dryRun = false;
        std::vector<std::string> wedges;
        std::string statusOf;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command =
        app.add_subcommand("farm", "Simulate and render a scene as jobs on a Slurm cluster (or here), with wedges of its values");
    addSceneOptions(*command, o->scene, false);
    command->add_option("-o,--output", o->output, "Output folder: frames, sim/, farm/ (scripts and logs)");
    command->add_option("--engine", o->engine, "slurm (sbatch) or local (the same scripts, one after another)")
        ->check(CLI::IsMember({"slurm", "local"}))
        ->capture_default_str();
    addFrameRangeOption(*command, o->frames, "Frames, A-B or A [default: the scene's range]");
    command
        ->add_option("--shards", o->shards,
                     "Simulate in K particle shards at once (the dynamic objects first, a merge after) [default: whole, "
                     "in one job]")
        ->check(CLI::Range(1, 100000));
    command->add_option("--chunk", o->chunk, "Frames per render task")->check(CLI::Range(1, 100000))->capture_default_str();
    command->add_option("--partition", o->partition, "Slurm partition [default: the cluster's]");
    command->add_option("--account", o->account, "Slurm account [default: yours]");
    command->add_option("--time", o->time, "Time limit per job, as sbatch takes it")->capture_default_str();
    command->add_option("--cpus-per-task", o->cpusPerTask, "Cores per job (the simulation's and each render task's threads)")
        ->check(CLI::Range(1, 4096))
        ->capture_default_str();
    command->add_option("--backend", o->backend, "Renderer of the render tasks: embree, povray or both")
        ->check(CLI::IsMember({"embree", "povray", "both"}))
        ->capture_default_str();
    command->add_option("--wedge", o->wedges,
                        "A variant per value: JSON pointer=VALUE,VALUE,... (as --set takes them; repeatable: every "
                        "combination), each into OUT/wedge-NN/");
    command->add_flag("--dry-run", o->dryRun, "Write and print the scripts, submit or run nothing");
    CLI::App* status = command->add_subcommand("status", "Frames simulated and rendered, jobs queued or running");
    status->add_option("folder", o->statusOf, "The farm's output folder")->required();

    return [o, status, &global] {
        if (status->parsed()) {
            for (const std::string& line : farmStatus(o->statusOf)) std::printf("%s\n", line.c_str());
            return;
        }
        if (o->scene.path.empty() || o->output.empty())
            throw CommandExit{2, "farm needs a scene and -o OUT (or: vfield farm status OUT)"};
        const Scene scene = loadScene(o->scene); // refuses a bad scene before anything is written
        FarmPlan plan;
        plan.vfield = fs::read_symlink("/proc/self/exe").string();
        plan.makeSheet = farmHelper("make-sheet");
        plan.scene = fs::absolute(o->scene.path).lexically_normal().string();
        plan.out = fs::absolute(o->output).lexically_normal().string();
        plan.overrides = o->scene.allOverrides();
        plan.renderArgs = {"--backend", o->backend};
        plan.first = o->frames ? o->frames->first : scene.simulation.firstFrame;
        plan.last = o->frames ? o->frames->last : scene.simulation.lastFrame;
        if (plan.first < scene.simulation.firstFrame || plan.last > scene.simulation.lastFrame)
            throw ValueError("frames " + std::to_string(plan.first) + "-" + std::to_string(plan.last) +
                             " lie outside the scene's " + std::to_string(scene.simulation.firstFrame) + "-" +
                             std::to_string(scene.simulation.lastFrame));
        plan.chunk = o->chunk;
        plan.shards = o->shards;
        plan.cpusPerTask = o->cpusPerTask;
        plan.partition = o->partition;
        plan.account = o->account;
        plan.time = o->time;
        plan.variants = wedgeVariants(plan.out, o->wedges);
        for (const FarmVariant& v : plan.variants) { // every variant must be a valid scene
            SceneCliOptions variant = o->scene;
            for (const auto& [pointer, value] : v.wedge) variant.overrides.push_back(pointer + "=" + value);
            loadScene(variant);
        }

        const std::vector<std::string> scripts = writeFarmScripts(plan);
        if (o->dryRun) {
            for (const std::string& script : scripts) {
                std::ifstream in(script);
                std::printf("==> %s <==\n%s\n", script.c_str(), std::string(std::istreambuf_iterator<char>(in), {}).c_str());
            }
            return;
        }
        if (o->engine == "local") {
            ProgressLine progress(global.quiet, "task");
            const Stopwatch watch;
            runLocally(
                plan, [&](int done, int total, const std::string& what) { progress.update(done, total, watch.seconds(), what); },
                global.quiet);
            log(global, plan.out + ": " + std::to_string(plan.variants.size()) + " variant(s) simulated and rendered here");
            return;
        }
        for (const std::string& line : submitToSlurm(plan)) log(global, line);
    };
}

} // namespace vfield::cli
