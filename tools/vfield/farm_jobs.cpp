#include "farm_jobs.h"

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace vfield::cli {

namespace {

/// A word for bash, single-quoted.
std::string quote(const std::string& word)
{
    std::string out = "'";
    for (const char c : word) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

std::string farmDir(const std::string& dir) { return dir + "/farm"; }

std::string frameName(const std::string& dir, int frame)
{
    char name[32];
    std::snprintf(name, sizeof name, "/frame.%04d.png", frame);
    return dir + name;
}

/// Splits "v1,v2,[1,2]" at the commas outside brackets and quotes.
std::vector<std::string> splitValues(const std::string& list)
{
    std::vector<std::string> values(1);
    int depth = 0;
    bool inString = false;
    for (std::size_t i = 0; i < list.size(); ++i) {
        const char c = list[i];
        if (inString) {
            if (c == '\\' && i + 1 < list.size()) values.back() += list[i++];
            else if (c == '"') inString = false;
        } else if (c == '"') inString = true;
        else if (c == '[' || c == '{') ++depth;
        else if (c == ']' || c == '}') --depth;
        else if (c == ',' && depth == 0) {
            values.emplace_back();
            continue;
        }
        values.back() += c;
    }
    return values;
}

std::string header(const FarmPlan& plan, const std::string& name, const std::string& log)
{
    std::string out = "#!/usr/bin/env bash\n";
    out += "#SBATCH --job-name=" + name + "\n";
    out += "#SBATCH --output=" + log + "\n";
    out += "#SBATCH --cpus-per-task=" + std::to_string(plan.cpusPerTask) + "\n";
    out += "#SBATCH --time=" + plan.time + "\n";
    if (!plan.partition.empty()) out += "#SBATCH --partition=" + plan.partition + "\n";
    if (!plan.account.empty()) out += "#SBATCH --account=" + plan.account + "\n";
    return out;
}

/// The scene's arguments for one variant: the user's --set, then the wedge's.
std::string sceneArguments(const FarmPlan& plan, const FarmVariant& variant)
{
    std::string out = quote(plan.scene);
    for (const std::string& o : plan.overrides) out += " --set " + quote(o);
    for (const auto& [pointer, value] : variant.wedge) out += " --set " + quote(pointer + "=" + value);
    return out;
}

std::string run(const std::string& command)
{
    std::FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) throw Error("cannot run: " + command);
    std::string out;
    std::array<char, 256> buffer;
    while (std::fgets(buffer.data(), int(buffer.size()), pipe)) out += buffer.data();
    const int status = pclose(pipe);
    if (status != 0) throw Error("`" + command + "` failed (status " + std::to_string(status) + "): " + out);
    return out;
}

/// sbatch --parsable prints "ID" or "ID;cluster".
std::string submit(const std::string& script, const std::string& dependency)
{
    std::string command = "sbatch --parsable";
    if (!dependency.empty()) command += " --dependency=afterok:" + dependency;
    std::string id = run(command + " " + quote(script));
    id = id.substr(0, id.find_first_of(";\n"));
    if (id.empty()) throw Error("sbatch printed no job id for " + script);
    return id;
}

} // namespace

std::string farmHelper(const std::string& name)
{
    const fs::path vfieldDir = fs::read_symlink("/proc/self/exe").parent_path();
    std::error_code buildTreeGone; // then this vfield is not the build tree's: false, not an error
    const bool isBuildTree = fs::equivalent(vfieldDir, VFIELD_BUILD_BIN_DIR, buildTreeGone);
    const fs::path helper =
        isBuildTree ? fs::path(VFIELD_SOURCE_TOOLS_DIR) / name : (vfieldDir / VFIELD_HELPERS_FROM_BIN / name).lexically_normal();
    if (::access(helper.c_str(), X_OK) != 0)
        throw FileError(helper.string(), "missing or not executable; the farm's jobs run it (is vfield installed whole?)");
    return helper.string();
}

std::vector<FarmStage> farmStages(const FarmPlan& plan)
{
    std::vector<FarmStage> stages;
    if (plan.shards == 0) stages.push_back({"simulate", 1});
    else stages.insert(stages.end(), {{"objects", 1}, {"shards", plan.shards}, {"merge", 1}});
    stages.insert(stages.end(), {{"render", plan.chunks()}, {"finish", 1}});
    return stages;
}

std::vector<FarmVariant> wedgeVariants(const std::string& out, const std::vector<std::string>& wedges)
{
    std::vector<FarmVariant> variants(1);
    variants.front().dir = out;
    if (wedges.empty()) return variants;
    for (const std::string& wedge : wedges) {
        const std::size_t equals = wedge.find('=');
        if (equals == std::string::npos || equals == 0 || equals + 1 == wedge.size())
            throw ValueError("--wedge " + wedge + ": expected POINTER=VALUE,VALUE,...");
        const std::string pointer = wedge.substr(0, equals);
        std::vector<FarmVariant> next;
        for (const FarmVariant& v : variants)
            for (const std::string& value : splitValues(wedge.substr(equals + 1))) {
                FarmVariant combined = v;
                combined.wedge.emplace_back(pointer, value);
                next.push_back(combined);
            }
        variants = next;
    }
    for (std::size_t i = 0; i < variants.size(); ++i) {
        char name[32];
        std::snprintf(name, sizeof name, "wedge-%02zu", i + 1);
        variants[i].name = name;
        variants[i].dir = out + "/" + name;
    }
    return variants;
}

std::vector<std::string> writeFarmScripts(const FarmPlan& plan)
{
    std::vector<std::string> scripts;
    nlohmann::json index = nlohmann::json::array();
    for (const FarmVariant& v : plan.variants) {
        const std::string dir = farmDir(v.dir);
        fs::create_directories(dir);
        const std::string tag = v.name.empty() ? "" : "-" + v.name;
        const std::string scene = sceneArguments(plan, v);
        const std::string range = std::to_string(plan.first) + "-" + std::to_string(plan.last);

        const std::string threads = " --threads \"${SLURM_CPUS_PER_TASK:-" + std::to_string(plan.cpusPerTask) + "}\"";
        // Sequential in time; a requeued job resumes after its last complete
        // frame, waiting for its earlier self to let go of the folder.
        const auto simulation = [&](const std::string& stage, const std::string& array, const std::string& arguments) {
            const std::string log = dir + "/" + stage + (array.empty() ? "-%j.log" : "-%A_%a.log");
            return header(plan, "vfield-" + stage + tag, log) + array + "#SBATCH --requeue\nset -euo pipefail\n" +
                   quote(plan.vfield) + " simulate " + scene + " -o " + quote(v.dir + "/sim") + " --wait --frames " + range +
                   threads + arguments + "\n";
        };
        // A chunk of frames per array task, one task at a time (a folder has
        // one writer); finished frames are skipped.
        std::string renderArgs;
        for (const std::string& a : plan.renderArgs) renderArgs += " " + quote(a);
        const std::string render = header(plan, "vfield-render" + tag, dir + "/render-%A_%a.log") + "#SBATCH --array=0-" +
                                   std::to_string(plan.chunks() - 1) + "%1\nset -euo pipefail\nfirst=$((" +
                                   std::to_string(plan.first) + " + ${SLURM_ARRAY_TASK_ID:?} * " + std::to_string(plan.chunk) +
                                   "))\nlast=$((first + " + std::to_string(plan.chunk - 1) + "))\n(( last > " +
                                   std::to_string(plan.last) + " )) && last=" + std::to_string(plan.last) + "\n" +
                                   quote(plan.vfield) + " render " + scene + " --sim " + quote(v.dir + "/sim") + " -o " +
                                   quote(v.dir) + " --wait --frames \"$first-$last\"" + threads + renderArgs + "\n";
        const std::string finish = header(plan, "vfield-finish" + tag, dir + "/finish-%j.log") + "set -euo pipefail\n" +
                                   quote(plan.makeSheet) + " " + quote(v.dir) + " " + quote(v.dir + "/contact.jpg") + " " +
                                   quote(v.dir + "/preview.mp4") + "\n";
        const std::string shards = std::to_string(plan.shards);
        const auto text = [&](const std::string& stage) {
            if (stage == "simulate") return simulation(stage, "", "");
            if (stage == "objects") return simulation(stage, "", " --shard objects");
            if (stage == "shards") // every shard at once: each moves its own particles into its own folder
                return simulation(stage, "#SBATCH --array=0-" + std::to_string(plan.shards - 1) + "\n",
                                  " --shard \"${SLURM_ARRAY_TASK_ID:?}/" + shards + "\"");
            if (stage == "merge") return simulation(stage, "", " --merge " + shards);
            return stage == "render" ? render : finish;
        };
        for (const FarmStage& stage : farmStages(plan)) {
            const std::string path = dir + "/" + stage.name + ".sh";
            writeTextAtomically(path, text(stage.name));
            fs::permissions(path, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add);
            scripts.push_back(path);
        }
        nlohmann::json overrides = nlohmann::json::object();
        for (const auto& [pointer, value] : v.wedge) overrides[pointer] = value;
        index.push_back({{"name", v.name}, {"folder", v.dir}, {"overrides", overrides}});
    }
    if (plan.isWedge()) {
        // The variants' last frames side by side, each labelled with its values.
        std::string tiles;
        for (const FarmVariant& v : plan.variants) {
            std::string label = v.name;
            for (const auto& [pointer, value] : v.wedge) label += " " + pointer + "=" + value;
            tiles += " " + quote(frameName(v.dir, plan.last)) + " " + quote(label);
        }
        const std::string sheet = header(plan, "vfield-wedges", farmDir(plan.out) + "/wedges-%j.log") + "set -euo pipefail\n" +
                                  quote(plan.makeSheet) + " --row " + quote(plan.out + "/wedges.jpg") + tiles + "\n";
        fs::create_directories(farmDir(plan.out));
        writeTextAtomically(farmDir(plan.out) + "/wedges.sh", sheet);
        scripts.push_back(farmDir(plan.out) + "/wedges.sh");
        writeTextAtomically(plan.out + "/wedges.json", index.dump(2) + "\n");
    }
    nlohmann::json status = {{"first", plan.first}, {"last", plan.last}, {"variants", index}};
    writeTextAtomically(farmDir(plan.out) + "/plan.json", status.dump(2) + "\n");
    return scripts;
}

std::vector<std::string> submitToSlurm(const FarmPlan& plan)
{
    std::vector<std::string> lines;
    std::string finishes;
    nlohmann::json jobs = nlohmann::json::array();
    for (const FarmVariant& v : plan.variants) {
        nlohmann::json job = {{"folder", v.dir}};
        std::string line = (v.name.empty() ? plan.out : v.dir) + ":", previous;
        for (const FarmStage& stage : farmStages(plan)) {
            previous = submit(farmDir(v.dir) + "/" + stage.name + ".sh", previous);
            job[stage.name] = previous;
            line +=
                " " + stage.name + " " + previous + (stage.tasks > 1 ? " (" + std::to_string(stage.tasks) + " tasks)" : "") + ",";
        }
        line.pop_back();
        finishes += (finishes.empty() ? "" : ":") + previous;
        jobs.push_back(job);
        lines.push_back(line);
    }
    if (plan.isWedge()) {
        const std::string sheet = submit(farmDir(plan.out) + "/wedges.sh", finishes);
        jobs.push_back({{"folder", plan.out}, {"wedges", sheet}});
        lines.push_back(plan.out + ": wedge sheet " + sheet);
    }
    writeTextAtomically(farmDir(plan.out) + "/jobs.json", jobs.dump(2) + "\n");
    return lines;
}

void runLocally(const FarmPlan& plan, const LocalTaskStarted& started, bool quiet)
{
    const std::vector<FarmStage> stages = farmStages(plan);
    int tasksPerVariant = 0;
    for (const FarmStage& stage : stages) tasksPerVariant += stage.tasks;
    const int total = int(plan.variants.size()) * tasksPerVariant + (plan.isWedge() ? 1 : 0);
    int done = 0;
    const auto runScript = [&](const std::string& what, const std::string& script, const std::string& environment) {
        started(done, total, what);
        // Quiet: the tasks' own progress goes to a log beside the script, as on a cluster.
        const std::string output = quiet ? " >> " + quote(script + ".log") + " 2>&1" : "";
        const int status = std::system((environment + " bash " + quote(script) + output).c_str());
        if (status != 0) throw Error(script + " failed (status " + std::to_string(status) + ")");
        ++done;
    };
    const std::string cpus = "SLURM_CPUS_PER_TASK=" + std::to_string(plan.cpusPerTask);
    for (const FarmVariant& v : plan.variants) {
        const std::string prefix = v.name.empty() ? "" : v.name + ": ";
        for (const FarmStage& stage : stages)
            for (int task = 0; task < stage.tasks; ++task) {
                const std::string script = farmDir(v.dir) + "/" + stage.name + ".sh";
                if (stage.tasks == 1) runScript(prefix + stage.name, script, cpus);
                else
                    runScript(prefix + stage.name + " task " + std::to_string(task + 1) + "/" + std::to_string(stage.tasks),
                              script, cpus + " SLURM_ARRAY_TASK_ID=" + std::to_string(task));
            }
    }
    if (plan.isWedge()) runScript("wedge sheet", farmDir(plan.out) + "/wedges.sh", cpus);
}

std::vector<std::string> farmStatus(const std::string& out)
{
    const std::string planPath = farmDir(out) + "/plan.json";
    std::ifstream planFile(planPath);
    if (!planFile) throw FileError(planPath, "no farm plan here (vfield farm SCENE -o " + out + " first)");
    nlohmann::json plan;
    try {
        plan = nlohmann::json::parse(planFile);
    } catch (const nlohmann::json::exception& e) {
        throw FileError(planPath, std::string("unreadable: ") + e.what());
    }
    const int first = plan.at("first").get<int>(), last = plan.at("last").get<int>();
    std::vector<std::string> lines;
    int missing = 0;
    for (const nlohmann::json& v : plan.at("variants")) {
        const std::string dir = v.at("folder").get<std::string>();
        int simulated = 0, rendered = 0;
        for (int frame = first; frame <= last; ++frame) {
            char density[40];
            std::snprintf(density, sizeof density, "/sim/density.%04d.vdb", frame);
            simulated += fs::exists(dir + density);
            rendered += fs::exists(frameName(dir, frame));
        }
        missing += (last - first + 1) - rendered;
        lines.push_back(dir + ": " + std::to_string(simulated) + " of " + std::to_string(last - first + 1) +
                        " frames simulated, " + std::to_string(rendered) + " rendered" +
                        (fs::exists(dir + "/contact.jpg") ? ", contact sheet and movie made" : ""));
        // A sharded simulation's parts, each as far as its stats.json records.
        std::vector<fs::path> parts;
        if (fs::is_directory(dir + "/sim/shards"))
            for (const auto& entry : fs::directory_iterator(dir + "/sim/shards")) parts.push_back(entry.path());
        std::sort(parts.begin(), parts.end());
        for (const fs::path& part : parts) {
            std::ifstream file(part / "stats.json");
            const nlohmann::json stats = nlohmann::json::parse(file, nullptr, false); // discarded when missing or torn
            int reached = 0;
            if (stats.is_object() && stats.contains("frames") && stats["frames"].is_array() && !stats["frames"].empty())
                reached = stats["frames"].back().value("frame", 0);
            lines.push_back("  part " + part.filename().string() + ": " +
                            (reached > 0 ? "frames up to " + std::to_string(reached) : std::string("nothing simulated yet")));
        }
    }
    std::ifstream jobsFile(farmDir(out) + "/jobs.json");
    if (jobsFile) {
        std::string ids;
        for (const nlohmann::json& job : nlohmann::json::parse(jobsFile))
            for (const auto& [key, value] : job.items())
                if (key != "folder") ids += (ids.empty() ? "" : ",") + value.get<std::string>();
        std::string queued;
        try {
            queued = run("squeue -h -j " + quote(ids) + " -o '%i %j %T' 2>/dev/null");
        } catch (const Error&) {
            queued = ""; // squeue refuses ids it no longer knows: all finished
        }
        std::istringstream in(queued);
        int count = 0;
        for (std::string line; std::getline(in, line); ++count) lines.push_back("  job " + line);
        lines.push_back(count == 0 ? "no job queued or running" : std::to_string(count) + " jobs queued or running");
    }
    lines.push_back(missing == 0 ? "done: every frame rendered" : std::to_string(missing) + " frames still to render");
    return lines;
}

} // namespace vfield::cli
