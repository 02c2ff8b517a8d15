// vfield golden record|check|update: golden-image regression tests for any
// shot. A case (golden/golden_case.h) names the vfield commands that make its
// outputs; check re-runs them as child processes and compares, update accepts
// new outputs on purpose, record makes a case from a scene.

#include "child_process.h"
#include "command.h"
#include "progress.h"
#include "scene_cli_options.h"

#include <vfield/core/error.h>
#include <vfield/core/stopwatch.h>
#include <vfield/golden/golden_case.h>
#include <vfield/golden/golden_check.h>
#include <vfield/golden/golden_report.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <unistd.h>

namespace fs = std::filesystem;

namespace vfield::cli {

namespace {

std::string today()
{
    const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
    std::tm utc{};
    gmtime_r(&now, &utc);
    char text[16];
    std::strftime(text, sizeof text, "%Y-%m-%d", &utc);
    return text;
}

/// Where the cases' outputs go: --work, or a folder of this process's under
/// the temporary folder, removed when every case passed.
struct WorkFolder {
    std::string path;
    bool temporary = false;

    explicit WorkFolder(const std::string& requested)
        : path(requested.empty() ? (fs::temp_directory_path() / ("vfield-golden-" + std::to_string(::getpid()))).string()
                                 : fs::absolute(requested).string()),
          temporary(requested.empty())
    {
        fs::create_directories(path);
    }
};

void appendToLog(const std::string& log, const std::string& text) { std::ofstream(log, std::ios::app) << text; }

/// Runs a case's commands into outDir (emptied first), showing the children's
/// progress. Returns an error message, or "" when every command succeeded.
std::string runCaseCommands(const std::string& name, const GoldenCase& c, const std::string& outDir,
                            const std::function<void(const std::string& line)>& progress)
{
    fs::remove_all(outDir);
    fs::create_directories(outDir);
    const std::string log = outDir + "/commands.log";
    for (const std::vector<std::string>& command : c.commandsFor(outDir)) {
        std::string commandLine = "vfield";
        for (const std::string& argument : command) commandLine += " " + argument;
        appendToLog(log, "$ " + commandLine + "\n");
        // The child's own progress without its timings (the parent's follow), shortened to fit a terminal's line.
        const int status = runVfield(command, log, [&](const std::string& output) {
            progress(name + ": " + command[0] + ": " + output.substr(0, std::min<std::size_t>(100, output.find("  elapsed "))));
        });
        if (status != 0)
            return "`" + commandLine + "` failed (exit " + std::to_string(status) + "): " + lastLogLine(log) + " (log: " + log +
                   ")";
    }
    return "";
}

/// Thresholds as `vfield compare` declares them, with the defaults a
/// recorded case starts from (one 8-bit step, as the project's own goldens).
void addThresholdOptions(CLI::App& command, ImageCompareOptions& o)
{
    o.failThreshold = 0.004;
    o.failPercent = 0.1;
    o.hardFail = 0.05;
    o.warnThreshold = 0.002;
    o.warnPercent = 0.5;
    command.add_option("--fail", o.failThreshold, "A pixel fails when a channel differs by more")->capture_default_str();
    command.add_option("--fail-percent", o.failPercent, "% of pixels allowed to fail")
        ->check(CLI::Range(0.0, 100.0))
        ->capture_default_str();
    command.add_option("--hard-fail", o.hardFail, "Fail if any channel differs by more")->capture_default_str();
    command.add_option("--warn", o.warnThreshold, "A pixel warns when a channel differs by more")->capture_default_str();
    command.add_option("--warn-percent", o.warnPercent, "% of pixels allowed to warn")
        ->check(CLI::Range(0.0, 100.0))
        ->capture_default_str();
    command.add_option("--diff-scale", o.diffScale, "Difference images show |golden - new| times this")->capture_default_str();
}

/// "1,120,240" or with ranges, "1-10,120".
std::vector<int> parseFrameList(const std::string& text)
{
    std::vector<int> frames;
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t comma = std::min(text.find(',', start), text.size());
        const std::string item = text.substr(start, comma - start);
        int first = 0, last = 0;
        char extra = 0;
        if (std::sscanf(item.c_str(), "%d-%d%c", &first, &last, &extra) == 2 && first <= last) {
            for (int f = first; f <= last; ++f) frames.push_back(f);
        } else if (std::sscanf(item.c_str(), "%d%c", &first, &extra) == 1) {
            frames.push_back(first);
        } else {
            throw CLI::ValidationError("--frames", "expected frames such as 1,120,240 or 1-10, got '" + text + "'");
        }
        start = comma + 1;
    }
    std::sort(frames.begin(), frames.end());
    frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
    if (frames.empty() || frames.front() < 0)
        throw CLI::ValidationError("--frames", "expected frame numbers >= 0, got '" + text + "'");
    return frames;
}

std::string frameName(const char* pattern, int frame)
{
    char name[64];
    std::snprintf(name, sizeof name, pattern, frame);
    return name;
}

Runner registerRecord(CLI::App& golden, const GlobalOptions& global)
{
    struct Options {
        SceneCliOptions scene;
        std::string frames, output, backend = "embree", formats = "png", why, work;
        bool grids = false, keepGrids = false;
        double gridTolerance = 0.0;
        ImageCompareOptions thresholds;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = golden.add_subcommand(
        "record", "Make a golden case for a shot: simulate and render its frames, keep the images as goldens");
    addSceneOptions(*command, o->scene);
    command->add_option("--frames", o->frames, "Frames to keep, e.g. 1,120,240 (ranges: 1-10)")
        ->required()
        ->check([](const std::string& text) {
            parseFrameList(text); // throws CLI::ValidationError, a usage error
            return std::string();
        });
    command->add_option("-o,--output", o->output, "The case folder to make (case.json and the goldens)")->required();
    addRenderShorthands(*command, o->scene);
    command->add_option("--backend", o->backend, "Renderer (povray runs single-threaded, to be reproducible)")
        ->check(CLI::IsMember({"embree", "povray"}))
        ->capture_default_str();
    command->add_option("--format", o->formats, "Goldens: png, or png,exr to keep the half-float EXR as well")
        ->check(CLI::IsMember({"png", "png,exr"}))
        ->capture_default_str();
    command->add_flag("--grids", o->grids, "Also record the checksums of the frames' density.####.vdb");
    command->add_flag("--keep-grids", o->keepGrids,
                      "Keep the frames' density.####.vdb beside the goldens, to compare voxels within --grid-tolerance "
                      "when checksums differ (implies --grids)");
    command->add_option("--grid-tolerance", o->gridTolerance, "Largest voxel difference accepted against a kept grid")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    command->add_option("--why", o->why, "What the case guards (kept in case.json)");
    command->add_option("--work", o->work, "Folder for the outputs [default: a temporary one, removed after]");
    addThresholdOptions(*command, o->thresholds);

    return [o, &global] {
        const std::vector<int> frames = parseFrameList(o->frames);
        const Scene scene = loadScene(o->scene);
        const fs::path folder = fs::absolute(o->output).lexically_normal();
        if (fs::exists(folder / "case.json"))
            throw Error(folder.string() + ": already holds a golden case (`vfield golden update` remakes its goldens)");

        GoldenCase c;
        c.folder = folder.string();
        c.why = o->why;
        c.scene = fs::relative(fs::absolute(o->scene.path), folder).string();
        c.compare = GoldenThresholds::from(o->thresholds);
        // The same overrides for both commands; the image's size and samples
        // are written out in full below, so that a changed default cannot change the case.
        std::vector<std::string> overrides;
        for (const std::string& value : o->scene.allOverrides())
            if (value.rfind("/render/resolution=", 0) != 0 && value.rfind("/render/samplesPerPixel=", 0) != 0)
                overrides.insert(overrides.end(), {"--set", value});
        std::vector<std::string> simulate = {"simulate", "@SCENE@",
                                             "-o",       "@OUT@/sim",
                                             "--frames", std::to_string(frames.front()) + "-" + std::to_string(frames.back())};
        simulate.insert(simulate.end(), overrides.begin(), overrides.end());
        c.commands.push_back(simulate);
        for (const int frame : frames) {
            std::vector<std::string> render = {"render",   "@SCENE@",      "--sim",     "@OUT@/sim",
                                               "-o",       "@OUT@/images", "--frames",  std::to_string(frame),
                                               "--format", o->formats,     "--backend", o->backend};
            if (o->backend == "povray") render.insert(render.end(), {"--povray-threads", "1"});
            render.insert(render.end(), overrides.begin(), overrides.end());
            const ImageSettings& image = scene.render.image;
            const std::vector<std::string> settings = {"--resolution",
                                                       std::to_string(image.width) + "x" + std::to_string(image.height), "--spp",
                                                       std::to_string(image.samplesPerPixel)};
            render.insert(render.end(), settings.begin(), settings.end());
            c.commands.push_back(render);
            c.images.push_back(frameName("images/frame.%04d.png", frame));
            if (o->formats == "png,exr") c.images.push_back(frameName("images/frame.%04d.exr", frame));
            if (o->grids || o->keepGrids)
                c.grids.push_back({frameName("sim/density.%04d.vdb", frame), "", o->keepGrids, o->gridTolerance});
        }

        const WorkFolder work(o->work);
        ProgressLine progress(global.quiet, "case");
        const Stopwatch watch;
        const std::string failure = runCaseCommands(folder.filename().string(), c, work.path, [&](const std::string& line) {
            progress.update(0, 1, watch.seconds(), line);
        });
        if (!failure.empty()) throw Error(failure);
        fs::create_directories(folder);
        acceptGoldenOutputs(c, work.path, today(), "recorded" + (o->why.empty() ? std::string() : ": " + o->why));
        if (work.temporary) fs::remove_all(work.path);
        std::printf("recorded %s: %zu images, %zu grids\n", c.caseFile().c_str(), c.images.size(), c.grids.size());
    };
}

/// The cases under the folders, or only those named (by their names under a
/// folder), in the order named. Throws Error for a name no folder holds.
std::vector<GoldenCaseRef> selectCases(const std::vector<std::string>& folders, const std::vector<std::string>& names)
{
    std::vector<GoldenCaseRef> found;
    for (const std::string& folder : folders) {
        const std::vector<GoldenCaseRef> cases = findGoldenCases(folder);
        found.insert(found.end(), cases.begin(), cases.end());
    }
    if (names.empty()) return found;
    std::vector<GoldenCaseRef> selected;
    for (const std::string& name : names) {
        const auto ref = std::find_if(found.begin(), found.end(), [&](const GoldenCaseRef& r) { return r.name == name; });
        if (ref == found.end()) throw Error("no golden case named " + name + " in " + folders.front());
        selected.push_back(*ref);
    }
    return selected;
}

/// Runs and compares every case; returns the results in the order found.
std::vector<GoldenCaseResult> checkCases(const std::vector<GoldenCaseRef>& cases, const WorkFolder& work,
                                         const GlobalOptions& global)
{
    std::vector<GoldenCaseResult> results;
    ProgressLine progress(global.quiet, "case");
    const Stopwatch total;
    for (const GoldenCaseRef& ref : cases) {
        const Stopwatch watch;
        const int done = int(results.size());
        const auto show = [&](const std::string& line) { progress.update(done, int(cases.size()), total.seconds(), line); };
        GoldenCaseResult result;
        try {
            const GoldenCase c = readGoldenCase(ref.folder);
            const std::string outDir = work.path + "/" + ref.name;
            const std::string failure = runCaseCommands(ref.name, c, outDir, show);
            if (failure.empty()) {
                result = compareGoldenOutputs(ref.name, c, outDir);
            } else {
                result.goldenCase = c;
                result.verdict = GoldenVerdict::Error;
                result.messages.push_back(failure);
            }
        } catch (const std::exception& e) {
            result.verdict = GoldenVerdict::Error;
            result.messages.push_back(e.what());
        }
        result.name = ref.name;
        result.seconds = watch.seconds();
        std::printf("%-5s %s (%.1f s)\n", goldenVerdictName(result.verdict), ref.name.c_str(), result.seconds);
        for (const std::string& message : result.messages) std::printf("      %s\n", message.c_str());
        std::fflush(stdout);
        results.push_back(std::move(result));
        progress.update(int(results.size()), int(cases.size()), total.seconds(), ref.name);
    }
    return results;
}

Runner registerCheck(CLI::App& golden, const GlobalOptions& global)
{
    struct Options {
        std::vector<std::string> folders, names;
        std::string work, junit, report;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = golden.add_subcommand(
        "check", "Re-simulate and re-render golden cases and compare with their goldens. Exit 0: all pass (warnings "
                 "included), 1: any fails, 2: an error");
    command->add_option("folders", o->folders, "Case folders, or folders holding cases (any depth)")->required();
    command->add_option("--work", o->work,
                        "Folder for the new outputs, one folder per case [default: a temporary one, "
                        "kept when a case fails]");
    command->add_option("--case", o->names, "Only this case, by its name under a folder (repeatable)");
    command->add_option("--junit", o->junit, "Write the results as JUnit XML");
    command->add_option("--report", o->report, "Write one self-contained HTML page: goldens, new images, differences");

    return [o, &global] {
        std::vector<GoldenCaseRef> cases;
        try {
            cases = selectCases(o->folders, o->names);
        } catch (const std::exception& e) {
            throw CommandExit{2, e.what()};
        }
        const WorkFolder work(o->work);
        const Stopwatch watch;
        const std::vector<GoldenCaseResult> results = checkCases(cases, work, global);
        try {
            if (!o->junit.empty()) writeJUnitReport(results, o->junit, watch.seconds());
            if (!o->report.empty()) writeHtmlReport(results, o->report);
        } catch (const std::exception& e) {
            throw CommandExit{2, e.what()};
        }
        const int failed = countVerdicts(results, GoldenVerdict::Fail), errors = countVerdicts(results, GoldenVerdict::Error);
        std::printf("%zu cases: %d passed, %d failed, %d errors\n", results.size(), int(results.size()) - failed - errors, failed,
                    errors);
        if (failed + errors == 0 && work.temporary) fs::remove_all(work.path);
        else if (failed + errors > 0) log(global, "new images and differences: " + work.path);
        if (errors > 0) throw CommandExit{2, ""};
        if (failed > 0) throw CommandExit{1, ""};
    };
}

Runner registerUpdate(CLI::App& golden, const GlobalOptions& global)
{
    struct Options {
        std::string folder, reason, work;
        std::vector<std::string> names;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = golden.add_subcommand(
        "update", "Accept new goldens on purpose: re-run the named cases, record the reason and how the images changed");
    command->add_option("folder", o->folder, "A case folder, or a folder holding cases")->required();
    command->add_option("--case", o->names, "Case to update, by its name under FOLDER (repeatable)")->required();
    command->add_option("--reason", o->reason, "Why the goldens change (kept in case.json)")->required();
    command->add_option("--work", o->work, "Folder for the new outputs [default: a temporary one, removed after]");

    return [o, &global] {
        const std::vector<GoldenCaseRef> cases = selectCases({o->folder}, o->names);
        const WorkFolder work(o->work);
        ProgressLine progress(global.quiet, "case");
        const Stopwatch watch;
        int done = 0;
        for (const GoldenCaseRef& ref : cases) {
            GoldenCase c = readGoldenCase(ref.folder);
            const std::string outDir = work.path + "/" + ref.name;
            const std::string failure = runCaseCommands(ref.name, c, outDir, [&](const std::string& line) {
                progress.update(done, int(cases.size()), watch.seconds(), line);
            });
            if (!failure.empty()) throw Error(failure);
            acceptGoldenOutputs(c, outDir, today(), o->reason);
            std::printf("updated %s\n", ref.name.c_str());
            for (const std::string& difference : c.regenerated.back().differences) std::printf("  %s\n", difference.c_str());
            ++done;
        }
        if (work.temporary) fs::remove_all(work.path);
    };
}

} // namespace

Runner registerGolden(CLI::App& app, const GlobalOptions& global)
{
    CLI::App* golden = app.add_subcommand("golden", "Golden-image regression tests for any shot: record, check, update");
    golden->require_subcommand(1);
    const std::map<std::string, Runner> runners = {
        {"record", registerRecord(*golden, global)},
        {"check", registerCheck(*golden, global)},
        {"update", registerUpdate(*golden, global)},
    };
    return [golden, runners] { runners.at(golden->get_subcommands().front()->get_name())(); };
}

} // namespace vfield::cli
