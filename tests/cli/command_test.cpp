#include "test_meshes.h"

#include <vfield/core/vdb_file.h>
#include <vfield/host/versions.h>
#include <vfield/mesh/mesh_io.h>
#include <vfield/render/povray/povray_runner.h>

#include <embree3/rtcore_config.h>
#include <openvdb/version.h>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <thread>

#include <nlohmann/json.hpp>

namespace {

using Run = vfield::test::CliRun;
using vfield::test::lineCount;
using vfield::test::runVfieldCli;

} // namespace

TEST_CASE("cli: a bad mesh is one error line and exit 1, bad usage is exit 2", "[cli]")
{
    const std::string dir = vfield::test::scratchDir("cli-errors");
    const Run missing = runVfieldCli("bake-field " + dir + "/none.obj -o " + dir + "/f.vdb", dir);
    CHECK(missing.exitCode == 1);
    CHECK(missing.err == "vfield bake-field: " + dir + "/none.obj: no such file\n");
    CHECK_FALSE(std::filesystem::exists(dir + "/f.vdb"));

    const Run unknown = runVfieldCli("bake-field mesh.obj -o f.vdb --max-levle 3", dir);
    CHECK(unknown.exitCode == 2);
    CHECK(lineCount(unknown.err) == 1);
    const Run none = runVfieldCli("", dir);
    CHECK(none.exitCode == 2);
}

TEST_CASE("cli: --version prints vfield's version and those of the libraries it runs with", "[cli]")
{
    const std::string dir = vfield::test::scratchDir("cli-version");
    const Run run = runVfieldCli("--version", dir);
    INFO(run.err);
    REQUIRE(run.exitCode == 0);
    const vfield::Versions versions = vfield::versions();
    CHECK(run.out == vfield::versionReport(versions) + "\n");
    CHECK(run.out.rfind("vfield " + versions.vfield + "\nOpenVDB ", 0) == 0);
    // The libraries that run are those vfield was built against.
    CHECK(versions.openvdb == OPENVDB_LIBRARY_VERSION_STRING);
    CHECK(versions.embree == RTC_VERSION_STRING);
    CHECK(versions.openImageIO == std::to_string(OIIO_VERSION_MAJOR) + "." + std::to_string(OIIO_VERSION_MINOR) + "." +
                                      std::to_string(OIIO_VERSION_PATCH));
    CHECK(versions.povray.has_value() == vfield::povrayAvailable());
    if (versions.povray) CHECK(versions.povray->rfind("3.7.", 0) == 0);
}

TEST_CASE("cli: every subcommand has help", "[cli]")
{
    const std::string dir = vfield::test::scratchDir("cli-help");
    // The subcommands as the top-level help lists them, so a new one is covered.
    const Run top = runVfieldCli("--help", dir);
    REQUIRE(top.exitCode == 0);
    std::vector<std::string> commands;
    std::istringstream lines(top.out.substr(top.out.find("Subcommands:")));
    for (std::string line; std::getline(lines, line);)
        if (line.rfind("  ", 0) == 0) commands.push_back(line.substr(2, line.find(' ', 2) - 2));
    CHECK(commands.size() == 17);
    for (const char* name : {"compare", "metrics", "farm", "export-scene", "help", "verify", "silhouette", "golden"})
        CHECK(std::find(commands.begin(), commands.end(), name) != commands.end());
    for (const std::string& command : commands) {
        const Run help = runVfieldCli(command + " --help", dir);
        INFO(command);
        CHECK(help.exitCode == 0);
        CHECK(help.out.find("Usage") != std::string::npos);
    }
}
