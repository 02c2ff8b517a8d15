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

TEST_CASE("cli: a bad scene is one line naming the file and the JSON path", "[cli]")
{
    const std::string dir = vfield::test::scratchDir("cli-bad-scene");
    std::ofstream(dir + "/s.json") << R"({"version": 1, "objects": [], "clouds": [{"count": -5}]})";
    const Run run = runVfieldCli("simulate " + dir + "/s.json -o " + dir + "/out", dir);
    CHECK(run.exitCode == 1);
    CHECK(run.err == "vfield simulate: " + dir + "/s.json: /clouds/0/count: expected a positive integer, got -5\n");
    CHECK_FALSE(std::filesystem::exists(dir + "/out"));
    const Run frames = runVfieldCli("simulate " + dir + "/s.json -o " + dir + "/out --frames 9-3", dir);
    CHECK(frames.exitCode == 2);

    // 100,000 nested arrays (200 kB) would overflow a recursive parser's stack: one line, exit 1, no output.
    std::ofstream(dir + "/deep.json") << std::string(100000, '[') << std::string(100000, ']');
    const Run deep = runVfieldCli("simulate " + dir + "/deep.json -o " + dir + "/out", dir);
    CHECK(deep.exitCode == 1);
    CHECK(deep.err ==
          "vfield simulate: " + dir + "/deep.json: line 1, column 257: JSON nested deeper than 256 arrays and objects\n");
    CHECK_FALSE(std::filesystem::exists(dir + "/out"));
}

TEST_CASE("cli: a scene estimated beyond --max-memory is refused at once, naming the key and the estimate", "[cli]")
{
    // A terrain of 8000 x 8000 cells would build for minutes, holding about
    // 15 GB, with nothing written; its estimate is 14.5 GiB (120 bytes a
    // triangle).
    const std::string dir = vfield::test::scratchDir("cli-max-memory");
    const std::string scene = std::string(VFIELD_SCENES_DIR) + "/cloud_over_terrain.json";
    const Run big = runVfieldCli("simulate " + scene + " -o " + dir +
                                     "/out --set '/objects/0/mesh/terrain/cells=[8000,8000]' "
                                     "--max-memory 4G",
                                 dir);
    CHECK(big.exitCode == 1);
    CHECK(big.err == "vfield simulate: " + scene +
                         ": /objects/0/mesh/terrain/cells: the scene needs about 14.5 GiB of memory, more than the limit "
                         "(4.0 GiB); 128096000 triangles here take 14.3 GiB (raise the limit with --max-memory)\n");
    CHECK_FALSE(std::filesystem::exists(dir + "/out"));
    // Raised past the estimate, the same limit lets the shipped scene through.
    const Run shipped = runVfieldCli("simulate " + scene + " -o " + dir + "/out --frames 1-1 --max-memory 512M --quiet", dir);
    CHECK(shipped.exitCode == 0);
    CHECK(runVfieldCli("simulate " + scene + " -o " + dir + "/out --max-memory 12Q", dir).exitCode == 2);
}

TEST_CASE("cli: a mesh file too large for the machine is refused before it is read", "[cli]")
{
    // A 64 GiB OBJ (sparse: it takes no disk) would be about 2 billion
    // triangles: more than any machine here holds, so probe refuses it from
    // its size, before reading a byte.
    const std::string dir = vfield::test::scratchDir("cli-huge-mesh");
    std::ofstream(dir + "/huge.obj").close();
    std::filesystem::resize_file(dir + "/huge.obj", 64ull << 30);
    std::ofstream(dir + "/points.csv") << "0,0,0\n";
    const Run run = runVfieldCli("probe " + dir + "/huge.obj --points " + dir + "/points.csv", dir);
    CHECK(run.exitCode == 1);
    CHECK(lineCount(run.err) == 1);
    CHECK_THAT(run.err, Catch::StartsWith("vfield probe: " + dir + "/huge.obj: loading it and building its field needs about "));
    CHECK_THAT(run.err, Catch::Contains("2147483648 triangles (by the file's size)"));
    std::filesystem::remove_all(dir);
}

TEST_CASE("cli: --set changes scene values and names a bad override", "[cli][scene]")
{
    const std::string dir = vfield::test::scratchDir("cli-set");
    std::ofstream(dir + "/s.json") << R"({"version": 1, "frames": {"start": 1, "end": 1, "fps": 24},
      "objects": [{"name": "ground", "mesh": {"box": {"min": [-20, -2, -20], "max": [20, 0, 20]}}}],
      "clouds": [{"count": 300, "center": [0, 6, 0], "radius": 2}]})";
    const auto simulate = [&](const std::string& set) {
        return runVfieldCli("simulate " + dir + "/s.json -o " + dir + "/sim " + set, dir);
    };
    REQUIRE(simulate("--set /clouds/0/count=120 -q").exitCode == 0);
    CHECK(vfield::test::readTextFile(dir + "/sim/stats.json").find("\"alive\": 120,") != std::string::npos);
    CHECK(simulate("--set /clouds/0/count=abc").err ==
          "vfield simulate: override /clouds/0/count=abc: the value is not JSON (a string needs its quotes)\n");
    CHECK(simulate("--set clouds=1").err == "vfield simulate: override clouds=1: a JSON pointer starts with '/'\n");
    CHECK(simulate("--set /clouds/0/count=-5").err ==
          "vfield simulate: " + dir + "/s.json: /clouds/0/count: expected a positive integer, got -5\n");
    CHECK(simulate("--set /clouds/0/count").exitCode == 2);
}

TEST_CASE("cli: shorthands are --set of a documented pointer, checked with the scene", "[cli][scene]")
{
    const std::string dir = vfield::test::scratchDir("cli-shorthands");
    std::ofstream(dir + "/s.json") << R"({"version": 1, "frames": {"start": 1, "end": 1, "fps": 24},
      "objects": [{"name": "ground", "mesh": {"box": {"min": [-20, -2, -20], "max": [20, 0, 20]}}}],
      "clouds": [{"count": 50, "center": [0, 6, 0], "radius": 2}], "render": {"resolution": [32, 18], "samplesPerPixel": 1}})";
    const Run simulated = runVfieldCli("simulate " + dir + "/s.json -o " + dir + "/sim --repulsion-method distance -q", dir);
    REQUIRE(simulated.exitCode == 0);
    CHECK(vfield::test::readTextFile(dir + "/sim/stats.json").find("\"method\": \"distance\"") != std::string::npos);
    CHECK(runVfieldCli("simulate " + dir + "/s.json -o " + dir + "/sim --repulsion-method sdf", dir).exitCode == 2);
    // --spp 0 is /render/samplesPerPixel's error, named as the scene's.
    const Run zero = runVfieldCli("render " + dir + "/s.json --sim " + dir + "/sim -o " + dir + "/img --spp 0", dir);
    CHECK(zero.exitCode == 1);
    CHECK(zero.err == "vfield render: " + dir + "/s.json: /render/samplesPerPixel: expected a positive integer, got 0\n");
    const Run size =
        runVfieldCli("render " + dir + "/s.json --sim " + dir + "/sim -o " + dir + "/img --resolution 20000x10", dir);
    CHECK(size.err.find("/render/resolution/0: expected a positive integer of at most 16384") != std::string::npos);
    CHECK(runVfieldCli("render " + dir + "/s.json --sim " + dir + "/sim -o " + dir + "/img --resolution 20x", dir).exitCode == 2);
    REQUIRE(
        runVfieldCli("render " + dir + "/s.json --sim " + dir + "/sim -o " + dir + "/img --resolution 24x12 -q", dir).exitCode ==
        0);
    OIIO::ImageBuf image(dir + "/img/frame.0001.png");
    CHECK(image.spec().width == 24);
}

TEST_CASE("cli: a heightmap with holes or absurd heights is refused at once, naming the pixel", "[cli][scene]")
{
    const std::string dir = vfield::test::scratchDir("cli-heightmap");
    // Two odd pixels, at (5, 6) and (2, 7), as an elevation model's holes are.
    const auto heightmap = [&](const std::string& name, float bad, float worse) {
        OIIO::ImageBuf image(OIIO::ImageSpec(8, 8, 1, OIIO::TypeDesc::FLOAT));
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 8; ++x) {
                const float h = x == 5 && y == 6 ? bad : x == 2 && y == 7 ? worse : 0.1f * float(x + y);
                image.setpixel(x, y, &h);
            }
        REQUIRE(image.write(dir + "/" + name));
    };
    heightmap("holes.exr", std::nanf(""), std::numeric_limits<float>::infinity());
    heightmap("absurd.exr", 1e30f, -1e30f);
    heightmap("valid.exr", 0.5f, 0.25f);
    const auto simulate = [&](const std::string& file, const std::string& extra) {
        std::ofstream(dir + "/s.json") << R"({"version": 1, "frames": {"start": 1, "end": 2},
          "objects": [{"name": "dem", "mesh": {"heightmap": {"file": ")" +
                                              file + R"(", "size": [40, 40], "heightScale": 60)" + extra + R"(}}}],
          "clouds": [{"count": 100, "center": [0, 90, 0], "radius": 3}]})";
        return runVfieldCli("simulate " + dir + "/s.json -o " + dir + "/sim-" + file + " -q", dir);
    };
    const Run holes = simulate("holes.exr", "");
    CHECK(holes.exitCode == 1);
    CHECK(holes.err.rfind("vfield simulate: " + dir + "/holes.exr: pixel (5, 6) holds NaN", 0) == 0);
    CHECK(lineCount(holes.err) == 1);
    const Run absurd = simulate("absurd.exr", "");
    CHECK(absurd.exitCode == 1);
    CHECK(absurd.err.find("absurd.exr: pixel (5, 6) is 1e+30, a height of 6e+31 world units") != std::string::npos);
    CHECK(simulate("holes.exr", R"(, "fillNoData": true)").exitCode == 0);
    CHECK(simulate("valid.exr", "").exitCode == 0);
}
