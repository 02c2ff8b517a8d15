// vfield: one binary, one subcommand per file (cmd_*.cpp). main parses,
// dispatches, and turns every failure into one line on stderr:
// exit 1 for errors, 2 for usage.

#include "command.h"

#include <vfield/host/versions.h>

#include <tbb/global_control.h>

#include <iostream>
#include <map>

namespace vfield::cli {

void log(const GlobalOptions& global, const std::string& line)
{
    if (!global.quiet) std::cerr << line << '\n';
}

std::shared_ptr<void> limitThreads(int threads)
{
    if (threads <= 0) return nullptr;
    return std::make_shared<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
}

} // namespace vfield::cli

namespace {

std::string oneLine(std::string text)
{
    for (char& c : text)
        if (c == '\n' || c == '\r') c = ' ';
    while (!text.empty() && text.back() == ' ') text.pop_back();
    return text;
}

} // namespace

int main(int argc, char** argv)
{
    using namespace vfield::cli;
    CLI::App app{"vfield: collision-free motion through octree vector fields, voxelized into OpenVDB."};
    app.require_subcommand(1);
    app.fallthrough(); // global options may follow the subcommand
    GlobalOptions global;
    app.add_flag("-q,--quiet", global.quiet, "No progress or log lines on stderr");
    app.set_version_flag(
        "--version", [] { return vfield::versionReport(vfield::versions()); },
        "Print vfield's version, those of OpenVDB, Embree, OpenImageIO and POV-Ray, and the OpenColorIO config it uses");

    const std::map<std::string, Runner> runners = {
        {"make-mesh", registerMakeMesh(app, global)},
        {"probe", registerProbe(app, global)},
        {"bake-field", registerBakeField(app, global)},
        {"field-slice", registerFieldSlice(app, global)},
        {"info", registerInfo(app, global)},
        {"simulate", registerSimulate(app, global)},
        {"export-mesh", registerExportMesh(app, global)},
        {"export-scene", registerExportScene(app, global)},
        {"render", registerRender(app, global)},
        {"run", registerRun(app, global)},
        {"compare", registerCompare(app, global)},
        {"metrics", registerMetrics(app, global)},
        {"farm", registerFarm(app, global)},
        {"help", registerHelp(app, global)},
        {"verify", registerVerify(app, global)},
        {"silhouette", registerSilhouette(app, global)},
        {"golden", registerGolden(app, global)},
    };

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::cerr << "vfield: " << oneLine(e.what()) << " (see vfield --help)\n";
        return 2;
    } catch (const std::exception& e) { // --version asks the libraries while parsing
        std::cerr << "vfield: " << oneLine(e.what()) << '\n';
        return 1;
    }

    const CLI::App* command = app.get_subcommands().front();
    try {
        runners.at(command->get_name())();
    } catch (const CommandExit& e) {
        if (!e.message.empty()) std::cerr << "vfield " << command->get_name() << ": " << oneLine(e.message) << '\n';
        return e.status;
    } catch (const std::exception& e) {
        std::cerr << "vfield " << command->get_name() << ": " << oneLine(e.what()) << '\n';
        return 1;
    }
    return 0;
}
