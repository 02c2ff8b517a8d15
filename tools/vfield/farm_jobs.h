#pragma once
// The jobs of `vfield farm`: a scene's simulation (whole, or sharded: the
// dynamic objects, the particles in K array tasks at once, a merge), its
// rendering in chunks of frames and its contact sheet and movie, as batch
// scripts that Slurm runs (sbatch, with dependencies) or that run one after
// another on this machine. Each script is plain bash with #SBATCH lines, so
// the same files serve both.

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace vfield::cli {

/// One variant of a wedge (or the only one): its folder and its overrides.
struct FarmVariant {
    std::string name;                                       ///< "wedge-01", or empty without wedges
    std::string dir;                                        ///< absolute: OUT, or OUT/wedge-NN
    std::vector<std::pair<std::string, std::string>> wedge; ///< pointer, JSON value
};

struct FarmPlan {
    std::string vfield;                  ///< absolute path of this vfield command
    std::string makeSheet;               ///< absolute path of tools/make-sheet (farmHelper)
    std::string scene, out;              ///< absolute
    std::vector<std::string> overrides;  ///< the user's --set, "POINTER=JSON"
    std::vector<std::string> renderArgs; ///< --backend and the like, passed to vfield render
    int first = 1, last = 1, chunk = 10;
    int shards = 0; ///< particle shards of the simulation (shard_part.h); 0: one job simulates it whole
    int cpusPerTask = 2;
    std::string partition, account, time = "04:00:00";
    std::vector<FarmVariant> variants;

    int chunks() const { return (last - first) / chunk + 1; }
    bool isWedge() const { return !variants.front().name.empty(); }
};

/// One of a variant's jobs: farm/NAME.sh, run once or as an array of tasks,
/// each job after the one before it.
struct FarmStage {
    std::string name; ///< simulate, or objects, shards and merge; then render and finish
    int tasks = 1;    ///< above 1: a Slurm array, SLURM_ARRAY_TASK_ID 0 .. tasks - 1
};
/// A variant's jobs, in the order they run.
std::vector<FarmStage> farmStages(const FarmPlan& plan);

/// The absolute path of a script the farm's jobs run (make-sheet). Installed,
/// it lies in <prefix>/libexec/vfield/, found from this vfield's own path
/// (<prefix>/bin/vfield), so a job never runs another copy's; only the vfield
/// the build tree made runs the source tree's tools/. Throws Error when it is
/// missing.
std::string farmHelper(const std::string& name);

/// The variants of the wedges ("POINTER=v1,v2,..." each; values are JSON,
/// split at commas outside brackets and quotes), every combination, in order.
std::vector<FarmVariant> wedgeVariants(const std::string& out, const std::vector<std::string>& wedges);

/// Writes OUT[/wedge-NN]/farm/STAGE.sh for each of farmStages (and for wedges
/// OUT/farm/wedges.sh, OUT/wedges.json) and OUT/farm/plan.txt. Returns the
/// scripts in the order they run.
std::vector<std::string> writeFarmScripts(const FarmPlan& plan);

/// Submits the scripts with sbatch, each variant's chain by dependencies, and
/// records the job ids in OUT/farm/jobs.txt. Returns one line per job.
std::vector<std::string> submitToSlurm(const FarmPlan& plan);

/// Told before each task runs locally: tasks done, tasks in all, and which ("render task 2/6").
using LocalTaskStarted = std::function<void(int done, int total, const std::string& what)>;

/// Runs the scripts here, one after another (the render script once per
/// chunk); quiet: each script's output goes to SCRIPT.log beside it.
void runLocally(const FarmPlan& plan, const LocalTaskStarted& started, bool quiet);

/// What OUT holds: per variant, frames simulated and rendered of the range,
/// and the Slurm jobs still queued or running.
std::vector<std::string> farmStatus(const std::string& out);

} // namespace vfield::cli
