#include "test_meshes.h"

#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>

namespace {

struct Run {
    int exitCode;
    std::string out, err;
};

std::string slurp(const std::string& path)
{
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

/// Runs the vfield binary with arguments (a shell-quoted string).
Run vfieldCli(const std::string& arguments, const std::string& dir)
{
    const std::string out = dir + "/stdout", err = dir + "/stderr";
    const std::string command = std::string(VFIELD_CLI_PATH) + " " + arguments + " >" + out + " 2>" + err;
    const int status = std::system(command.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

int lineCount(const std::string& text) { return int(std::count(text.begin(), text.end(), '\n')); }

} // namespace

TEST_CASE("cli: probe prints the octree's force at each point", "[cli]")
{
    const std::string dir = vfield::test::scratchDir("cli-probe");
    std::ofstream(dir + "/points.csv") << "x,y,z\n0.75,0.75,0.75\n\n# outside\n2,2,2\n";
    const Run probe = vfieldCli("probe " + vfield::test::dataPath("cube_quads.obj") + " --margin 0 --points " + dir +
                                    "/points.csv --quiet",
                                dir);
    INFO(probe.err);
    REQUIRE(probe.exitCode == 0);
    // The unit cube's (+,+,+) octant: three faces, (1,1,1)/sqrt(3) x level 2 x boost 10,
    // printed at float precision as the field stores it.
    CHECK(probe.out == "x,y,z,fx,fy,fz,level,surface\n"
                       "0.75,0.75,0.75,11.5470047,11.5470047,11.5470047,2,1\n"
                       "2,2,2,0,0,0,0,0\n");
    CHECK(probe.err.empty());
}

TEST_CASE("cli: a malformed points file is one error line naming the line", "[cli]")
{
    const std::string dir = vfield::test::scratchDir("cli-bad-points");
    std::ofstream(dir + "/points.csv") << "1,2,3\n4,five,6\n";
    const Run run = vfieldCli("probe " + vfield::test::dataPath("cube_quads.obj") + " --points " + dir + "/points.csv", dir);
    CHECK(run.exitCode == 1);
    CHECK(run.err == "vfield probe: " + dir + "/points.csv: line 2: expected three numbers x,y,z\n");
}

TEST_CASE("cli: a bad mesh is one error line and exit 1; bad usage is exit 2", "[cli]")
{
    const std::string dir = vfield::test::scratchDir("cli-errors");
    const Run missing = vfieldCli("bake-field " + dir + "/none.obj -o " + dir + "/f.vdb", dir);
    CHECK(missing.exitCode == 1);
    CHECK(missing.err == "vfield bake-field: " + dir + "/none.obj: no such file\n");
    CHECK_FALSE(std::filesystem::exists(dir + "/f.vdb"));

    const Run unknown = vfieldCli("bake-field mesh.obj -o f.vdb --max-levle 3", dir);
    CHECK(unknown.exitCode == 2);
    CHECK(lineCount(unknown.err) == 1);
    const Run none = vfieldCli("", dir);
    CHECK(none.exitCode == 2);
}

TEST_CASE("cli: every subcommand has help", "[cli]")
{
    const std::string dir = vfield::test::scratchDir("cli-help");
    for (const char* command : {"make-mesh", "probe", "bake-field", "field-slice", "info"}) {
        const Run help = vfieldCli(std::string(command) + " --help", dir);
        INFO(command);
        CHECK(help.exitCode == 0);
        CHECK(help.out.find("Usage") != std::string::npos);
    }
}

TEST_CASE("cli: make-mesh then bake-field then info and field-slice chain into files", "[cli]")
{
    const std::string dir = vfield::test::scratchDir("cli-chain");
    REQUIRE(vfieldCli("make-mesh -o " + dir + "/t.obj terrain --cells-x 32 --cells-z 32", dir).exitCode == 0);
    REQUIRE(vfieldCli("bake-field " + dir + "/t.obj -o " + dir + "/a.vdb --max-level 6", dir).exitCode == 0);
    REQUIRE(vfieldCli("bake-field " + dir + "/t.obj -o " + dir + "/b.vdb --max-level 6 -q", dir).exitCode == 0);

    const Run a = vfieldCli("info --checksum " + dir + "/a.vdb", dir), b = vfieldCli("info --checksum " + dir + "/b.vdb", dir);
    REQUIRE(a.exitCode == 0);
    CHECK(lineCount(a.out) == 3);
    CHECK(a.out.rfind("force", 0) == 0);
    CHECK(a.out.find("vec3s") != std::string::npos);
    CHECK(a.out == b.out); // same contents, whatever the file ids

    const Run slice = vfieldCli("field-slice " + dir + "/t.obj --axis x --at 0 --size 256 -o " + dir + "/s.png", dir);
    INFO(slice.err);
    CHECK(slice.exitCode == 0);
    CHECK(std::filesystem::file_size(dir + "/s.png") > 1000);
}
