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

TEST_CASE("cli: probe prints the octree's force at each point", "[cli]")
{
    const std::string dir = vfield::test::scratchDir("cli-probe");
    std::ofstream(dir + "/points.csv") << "x,y,z\n0.75,0.75,0.75\n\n# outside\n2,2,2\n";
    const Run probe = runVfieldCli(
        "probe " + vfield::test::dataPath("cube_quads.obj") + " --margin 0 --points " + dir + "/points.csv --quiet", dir);
    INFO(probe.err);
    REQUIRE(probe.exitCode == 0);
    // The unit cube's (+,+,+) octant: three faces, (1,1,1)/sqrt(3) x level 2 x boost 10,
    // printed at float precision as the field stores it.
    CHECK(probe.out == "x,y,z,fx,fy,fz,level,surface\n"
                       "0.75,0.75,0.75,11.5470047,11.5470047,11.5470047,2,1\n"
                       "2,2,2,0,0,0,0,0\n");
    CHECK(probe.err.empty());
    // Split down to level 3, where the growths part: strength 3 x 3 x boost 10
    // (linear) against 3 x 2^(3 - 1) x 10 (doubling), along the diagonal.
    const auto probeAtLevel3 = [&](const std::string& growth) {
        return runVfieldCli("probe " + vfield::test::dataPath("cube_quads.obj") +
                                " --margin 0 --max-per-leaf 1 --max-level 3 --strength 3 --growth " + growth + " --points " +
                                dir + "/points.csv --quiet",
                            dir)
            .out;
    };
    CHECK(probeAtLevel3("linear").find("0.75,0.75,0.75,51.961525,51.961525,51.961525,3,1\n") != std::string::npos);
    CHECK(probeAtLevel3("doubling").find("0.75,0.75,0.75,69.2820282,69.2820282,69.2820282,3,1\n") != std::string::npos);
    CHECK(
        runVfieldCli("probe " + vfield::test::dataPath("cube_quads.obj") + " --growth cubic --points " + dir + "/points.csv", dir)
            .exitCode != 0);
}

TEST_CASE("cli: an inside-out mesh is oriented outward with a warning, and --flip-normals turns it", "[cli]")
{
    // Every triangle of make-mesh's sphere reversed: its field pulled objects in
    // ((-4.9, -0.6, -0.7) at (1.15, 0, 0)).
    const std::string dir = vfield::test::scratchDir("cli-inside-out");
    REQUIRE(runVfieldCli("make-mesh sphere -o " + dir + "/sphere.obj -q", dir).exitCode == 0);
    std::istringstream lines(vfield::test::readTextFile(dir + "/sphere.obj"));
    std::ofstream inverted(dir + "/inverted.obj");
    for (std::string line; std::getline(lines, line);) {
        if (line.rfind("f ", 0) == 0) {
            std::istringstream f(line.substr(2));
            std::string a, b, c;
            f >> a >> b >> c;
            inverted << "f " << a << ' ' << c << ' ' << b << '\n';
        } else {
            inverted << line << '\n';
        }
    }
    inverted.close();
    std::ofstream(dir + "/points.csv") << "1.15,0,0\n";
    const auto forceX = [&](const std::string& options, std::string* err = nullptr) {
        const Run probe = runVfieldCli("probe " + dir + "/inverted.obj --points " + dir + "/points.csv " + options, dir);
        REQUIRE(probe.exitCode == 0);
        if (err) *err = probe.err;
        // The second line, "x,y,z,fx,fy,fz,level,surface": its fourth value.
        std::istringstream values(probe.out.substr(probe.out.find('\n') + 1));
        std::string value;
        for (int column = 0; column < 4; ++column) std::getline(values, value, ',');
        return std::stod(value);
    };
    std::string err;
    CHECK(forceX("", &err) > 1.0);
    CHECK(err.find(dir + "/inverted.obj: closed mesh oriented outward (1 inside-out pieces turned") != std::string::npos);
    CHECK(forceX("--flip-normals -q") < -1.0);
}

TEST_CASE("cli: a malformed points file is one error line naming the line", "[cli]")
{
    const std::string dir = vfield::test::scratchDir("cli-bad-points");
    std::ofstream(dir + "/points.csv") << "1,2,3\n4,five,6\n";
    const Run run = runVfieldCli("probe " + vfield::test::dataPath("cube_quads.obj") + " --points " + dir + "/points.csv", dir);
    CHECK(run.exitCode == 1);
    CHECK(run.err == "vfield probe: " + dir + "/points.csv: line 2: expected three numbers x,y,z\n");
}

TEST_CASE("cli: make-mesh then bake-field then info and field-slice chain into files", "[cli]")
{
    const std::string dir = vfield::test::scratchDir("cli-chain");
    REQUIRE(runVfieldCli("make-mesh -o " + dir + "/t.obj terrain --cells-x 32 --cells-z 32", dir).exitCode == 0);
    REQUIRE(runVfieldCli("bake-field " + dir + "/t.obj -o " + dir + "/a.vdb --max-level 6", dir).exitCode == 0);
    REQUIRE(runVfieldCli("bake-field " + dir + "/t.obj -o " + dir + "/b.vdb --max-level 6 -q", dir).exitCode == 0);

    const Run a = runVfieldCli("info --checksum " + dir + "/a.vdb", dir),
              b = runVfieldCli("info --checksum " + dir + "/b.vdb", dir);
    REQUIRE(a.exitCode == 0);
    CHECK(lineCount(a.out) == 3);
    CHECK(a.out.rfind("force", 0) == 0);
    CHECK(a.out.find("vec3s") != std::string::npos);
    CHECK(a.out == b.out); // same contents, whatever the file ids

    const Run slice = runVfieldCli("field-slice " + dir + "/t.obj --axis x --at 0 --size 256 -o " + dir + "/s.png", dir);
    INFO(slice.err);
    CHECK(slice.exitCode == 0);
    CHECK(std::filesystem::file_size(dir + "/s.png") > 1000);
}

TEST_CASE("cli: --scene and --object draw an object's field as the scene makes it, the flags changing it", "[cli]")
{
    const std::string dir = vfield::test::scratchDir("cli-scene-object");
    std::ofstream(dir + "/s.json") << R"({"version": 1, "objects": [
      {"name": "cube", "mesh": {"file": ")" +
                                          vfield::test::dataPath("cube_quads.obj") + R"("},
       "repulsion": {"margin": 0, "maxPerLeaf": 1, "maxLevel": 3, "strength": 3, "growth": "doubling"}}]})";
    std::ofstream(dir + "/points.csv") << "0.75,0.75,0.75\n";
    const Run fromScene = runVfieldCli("probe --scene " + dir + "/s.json --object cube --points " + dir + "/points.csv -q", dir);
    const Run fromFlags = runVfieldCli("probe " + vfield::test::dataPath("cube_quads.obj") +
                                           " --margin 0 --max-per-leaf 1 --max-level 3 --strength 3 --growth doubling --points " +
                                           dir + "/points.csv -q",
                                       dir);
    INFO(fromScene.err);
    REQUIRE(fromScene.exitCode == 0);
    CHECK(fromScene.out == fromFlags.out);
    CHECK(fromScene.out.find("69.2820282") != std::string::npos);
    // A flag changes the scene's value, checked as the scene's.
    const Run linear =
        runVfieldCli("probe --scene " + dir + "/s.json --object cube --growth linear --points " + dir + "/points.csv -q", dir);
    CHECK(linear.out.find("51.961525") != std::string::npos);
    const Run deep =
        runVfieldCli("probe --scene " + dir + "/s.json --object cube --max-level 30 --points " + dir + "/points.csv", dir);
    CHECK(deep.err ==
          "vfield probe: " + dir + "/s.json: /objects/0/repulsion/maxLevel: expected a positive integer of at most 20, got 30\n");
    CHECK(runVfieldCli("probe --scene " + dir + "/s.json --object sphere --points " + dir + "/points.csv", dir)
              .err.find("no object named \"sphere\" (its objects: cube)") != std::string::npos);
    CHECK(runVfieldCli("probe --scene " + dir + "/s.json --points " + dir + "/points.csv", dir).exitCode == 2);
    CHECK(runVfieldCli("probe --points " + dir + "/points.csv", dir).exitCode == 2);
}
