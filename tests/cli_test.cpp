#include "test_meshes.h"

#include <vfield/core/vdb_file.h>
#include <vfield/mesh/mesh_io.h>
#include <vfield/render/povray/povray_runner.h>
#include <vfield/scene/versions.h>

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
using vfield::test::runVfieldCli;

int lineCount(const std::string& text) { return int(std::count(text.begin(), text.end(), '\n')); }

/// What `vfield silhouette` printed: the outline's dimension, the cloud's share of the pixels.
struct SilhouetteLine {
    double dimension = 0.0, percent = 0.0;
};
SilhouetteLine silhouetteOf(const Run& measure)
{
    REQUIRE(measure.exitCode == 0);
    INFO(measure.out);
    SilhouetteLine line;
    REQUIRE(std::sscanf(measure.out.c_str(), "dimension %lf, cloud %lf%%", &line.dimension, &line.percent) == 2);
    return line;
}

/// The silhouette tests' disk, 60 pixels in radius in a 256x256 frame, as measured.
void checkIsTheDisk(const Run& measure)
{
    INFO(measure.out);
    const SilhouetteLine disk = silhouetteOf(measure);
    CHECK(disk.dimension == Approx(1.0).margin(0.06));
    CHECK(disk.percent == Approx(100.0 * M_PI * 60 * 60 / (256 * 256)).epsilon(0.02));
}

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

    // 100,000 nested arrays (200 kB) crashed the parser; now one line, exit 1, no output.
    std::ofstream(dir + "/deep.json") << std::string(100000, '[') << std::string(100000, ']');
    const Run deep = runVfieldCli("simulate " + dir + "/deep.json -o " + dir + "/out", dir);
    CHECK(deep.exitCode == 1);
    CHECK(deep.err ==
          "vfield simulate: " + dir + "/deep.json: line 1, column 257: JSON nested deeper than 256 arrays and objects\n");
    CHECK_FALSE(std::filesystem::exists(dir + "/out"));
}

TEST_CASE("cli: a scene estimated beyond --max-memory is refused at once, naming the key and the estimate", "[cli]")
{
    // A terrain of 8000 x 8000 cells was still building after 120 s with 15 GB
    // resident and nothing written; its estimate is 14.5 GiB (120 bytes a
    // triangle, measured).
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

TEST_CASE("cli: simulate writes frames, tells each step before them and each frame with an ETA, and export-mesh places objects",
          "[cli]")
{
    const std::string dir = vfield::test::scratchDir("cli-simulate");
    std::ofstream(dir + "/s.json") << R"({"version": 1, "frames": {"start": 1, "end": 4, "fps": 24},
      "objects": [{"name": "ground", "mesh": {"box": {"min": [-20, -2, -20], "max": [20, 0, 20]}},
                   "transform": {"translate": [0, -1, 0]}, "repulsion": {"maxLevel": 5}},
                  {"name": "dart", "mesh": {"box": {"min": [-1, -0.2, -0.2], "max": [1, 0.2, 0.2]}},
                   "motion": "dynamic", "velocity": [0, 0, -10], "transform": {"translate": [0, 5, 0]}}],
      "clouds": [{"count": 500, "center": [0, 6, 0], "radius": 2}],
      "fields": [{"acceleration": [0, -9.81, 0]}]})";
    const Run run = runVfieldCli("simulate " + dir + "/s.json -o " + dir + "/out --frames 2-4", dir);
    INFO(run.err);
    REQUIRE(run.exitCode == 0);
    CHECK(run.err.find("frame 4/4") != std::string::npos); // plain progress lines when not a terminal
    CHECK(run.err.find("ETA ") != std::string::npos);
    // What it prepares before the first frame is told as it starts, in order.
    const std::size_t field = run.err.find("preparing: ground: octree field of 12 triangles"),
                      distance = run.err.find("preparing: ground: exact distance field 99%"),
                      firstFrame = run.err.find("frame 1/4");
    CHECK(field < distance);
    CHECK(distance < firstFrame);
    CHECK(run.err.find("clearance of particles: min") != std::string::npos);
    for (const char* name :
         {"field.vdb", "density.0002.vdb", "density.0004.vdb", "particles.0004.vdb", "tracks.json", "stats.json"})
        CHECK(std::filesystem::exists(dir + "/out/" + name));
    CHECK_FALSE(std::filesystem::exists(dir + "/out/density.0001.vdb"));

    const Run quiet = runVfieldCli("simulate " + dir + "/s.json -o " + dir + "/out2 --quiet", dir);
    CHECK(quiet.err.empty());

    REQUIRE(runVfieldCli("export-mesh " + dir + "/s.json --object ground -o " + dir + "/g.obj", dir).exitCode == 0);
    CHECK(vfield::test::readTextFile(dir + "/g.obj").find("v -20 -3 -20") != std::string::npos); // world space
    REQUIRE(runVfieldCli("export-mesh " + dir + "/s.json --object dart --frame 4 --sim " + dir + "/out -o " + dir + "/d.obj", dir)
                .exitCode == 0);
    const Run missing = runVfieldCli("export-mesh " + dir + "/s.json --object plane -o " + dir + "/p.obj", dir);
    CHECK(missing.exitCode == 1);
    CHECK(missing.err == "vfield export-mesh: " + dir + "/s.json: no object named \"plane\"\n");
}

TEST_CASE("cli: render refuses bad simulations with one line and writes no image", "[cli][render]")
{
    const std::string dir = vfield::test::scratchDir("cli-render-bad");
    std::ofstream(dir + "/s.json") << R"({"version": 1, "frames": {"start": 1, "end": 3, "fps": 24},
      "objects": [{"name": "ground", "mesh": {"box": {"min": [-20, -2, -20], "max": [20, 0, 20]}}}],
      "clouds": [{"count": 300, "center": [0, 6, 0], "radius": 2}],
      "camera": {"position": [0, 10, 40], "lookAt": [0, 2, 0]}, "render": {"resolution": [64, 36], "samplesPerPixel": 1}})";
    const auto render = [&](const std::string& sim) {
        return runVfieldCli("render " + dir + "/s.json --sim " + sim + " -o " + dir + "/img --frames 2", dir);
    };
    const Run noSim = render(dir + "/none");
    CHECK(noSim.exitCode == 1);
    CHECK(noSim.err == "vfield render: " + dir + "/none: no such simulation folder\n");

    REQUIRE(runVfieldCli("simulate " + dir + "/s.json -o " + dir + "/sim -q", dir).exitCode == 0);
    const Run good = render(dir + "/sim");
    INFO(good.err);
    CHECK(good.exitCode == 0);
    CHECK(std::filesystem::exists(dir + "/img/frame.0002.png"));
    const auto written = std::filesystem::last_write_time(dir + "/img/frame.0002.png");
    const Run again = render(dir + "/sim"); // a finished frame is skipped
    CHECK(again.err.find("rendered 0 frames") != std::string::npos);
    CHECK(again.err.find("skipped 1") != std::string::npos);
    CHECK(std::filesystem::last_write_time(dir + "/img/frame.0002.png") == written);
    // A frame simulated again since (an edited scene is simulated afresh) is rendered again. The
    // image is made older than the simulation rather than the simulation newer than now: a frame
    // rendered within that second would still be older than the simulation, and rendered again.
    std::filesystem::last_write_time(dir + "/img/frame.0002.png",
                                     std::filesystem::last_write_time(dir + "/sim/density.0002.vdb") - std::chrono::seconds(1));
    CHECK(render(dir + "/sim").err.find("rendered 1 frame") != std::string::npos);
    // A frame rendered with other settings is rendered again, then kept.
    const auto renderAt = [&](const std::string& size) {
        return runVfieldCli("render " + dir + "/s.json --sim " + dir + "/sim -o " + dir + "/img --frames 2 --resolution " + size,
                            dir);
    };
    CHECK(renderAt("32x18").err.find("rendered 1 frame") != std::string::npos);
    CHECK(renderAt("32x18").err.find("skipped 1") != std::string::npos);
    CHECK(render(dir + "/sim").err.find("rendered 1 frame") != std::string::npos);
    std::filesystem::remove_all(dir + "/img");

    std::filesystem::remove(dir + "/sim/density.0002.vdb");
    const Run missing = render(dir + "/sim");
    CHECK(missing.exitCode == 1);
    CHECK(missing.err == "vfield render: " + dir + "/sim/density.0002.vdb: missing (simulate these frames first)\n");

    std::ofstream(dir + "/sim/density.0002.vdb") << "not a vdb";
    const Run corrupt = render(dir + "/sim");
    CHECK(corrupt.exitCode == 1);
    CHECK(corrupt.err.rfind("vfield render: " + dir + "/sim/density.0002.vdb: ", 0) == 0);
    CHECK(lineCount(corrupt.err) == 1);

    // A VDB without a density grid, and one with a NaN voxel.
    openvdb::initialize();
    openvdb::FloatGrid::Ptr other = openvdb::FloatGrid::create(0.0f);
    other->setName("temperature");
    vfield::writeVdb(dir + "/sim/density.0002.vdb", {other});
    CHECK(render(dir + "/sim").err == "vfield render: " + dir + "/sim/density.0002.vdb: no grid named 'density'\n");
    openvdb::FloatGrid::Ptr nan = openvdb::FloatGrid::create(0.0f);
    nan->setName("density");
    nan->tree().setValue(openvdb::Coord(1, 2, 3), std::nanf(""));
    vfield::writeVdb(dir + "/sim/density.0002.vdb", {nan});
    CHECK(render(dir + "/sim").err ==
          "vfield render: " + dir + "/sim/density.0002.vdb: grid 'density' holds a non-finite value at voxel (1, 2, 3)\n");
    CHECK_FALSE(std::filesystem::exists(dir + "/img/frame.0002.png"));

    // A frame of another simulation (another seed) is refused, named.
    REQUIRE(runVfieldCli("simulate " + dir + "/s.json -o " + dir + "/other --set /seed=7 -q", dir).exitCode == 0);
    REQUIRE(runVfieldCli("simulate " + dir + "/s.json -o " + dir + "/sim -q", dir).exitCode == 0);
    std::filesystem::copy_file(dir + "/other/density.0002.vdb", dir + "/sim/density.0002.vdb",
                               std::filesystem::copy_options::overwrite_existing);
    const Run foreign = render(dir + "/sim");
    CHECK(foreign.exitCode == 1);
    CHECK(foreign.err.rfind("vfield render: " + dir + "/sim/density.0002.vdb: was made by another simulation (inputs hash ", 0) ==
          0);
    CHECK(lineCount(foreign.err) == 1);
}

TEST_CASE("cli: verify names a folder's frames that are missing, made by another simulation or damaged", "[cli][resume]")
{
    const std::string dir = vfield::test::scratchDir("cli-verify");
    std::ofstream(dir + "/s.json") << R"({"version": 1, "frames": {"start": 1, "end": 4, "fps": 24},
      "objects": [{"name": "ground", "mesh": {"box": {"min": [-20, -2, -20], "max": [20, 0, 20]}}}],
      "clouds": [{"count": 300, "center": [0, 6, 0], "radius": 2}]})";
    REQUIRE(runVfieldCli("simulate " + dir + "/s.json -o " + dir + "/sim -q", dir).exitCode == 0);
    REQUIRE(runVfieldCli("simulate " + dir + "/s.json -o " + dir + "/other --set /seed=7 -q", dir).exitCode == 0);
    const Run clean = runVfieldCli("verify " + dir + "/sim", dir);
    CHECK(clean.exitCode == 0);
    CHECK(clean.out.empty());
    CHECK(clean.err.find("4 frames recorded, 4 good, 0 missing, 0 foreign, 0 corrupt") != std::string::npos);

    std::filesystem::remove(dir + "/sim/density.0002.vdb");
    std::filesystem::copy_file(dir + "/other/particles.0003.vdb", dir + "/sim/particles.0003.vdb",
                               std::filesystem::copy_options::overwrite_existing);
    std::ofstream(dir + "/sim/density.0004.vdb", std::ios::app) << "trailing bytes";
    const Run damaged = runVfieldCli("verify " + dir + "/sim", dir);
    CHECK(damaged.exitCode == 1);
    CHECK(damaged.out.find("frame 2: missing: " + dir + "/sim/density.0002.vdb is missing\n") != std::string::npos);
    CHECK(damaged.out.find("frame 3: foreign: " + dir + "/sim/particles.0003.vdb was made by another simulation") !=
          std::string::npos);
    CHECK(damaged.out.find("frame 4: corrupt: " + dir + "/sim/density.0004.vdb has ") != std::string::npos);
    CHECK(damaged.err.find("4 frames recorded, 1 good, 1 missing, 1 foreign, 1 corrupt") != std::string::npos);
}

namespace {

/// Starts `vfield arguments` in the background; returns its process id once
/// it holds the lock of folder (its lock file names it).
pid_t startHolding(const std::string& arguments, const std::string& folder, const std::string& dir)
{
    const std::string pidFile = dir + "/background.pid";
    std::filesystem::remove(pidFile);
    std::system((std::string(VFIELD_CLI_PATH) + " " + arguments + " -q >/dev/null 2>&1 & echo $! > " + pidFile).c_str());
    for (int wait = 0; wait < 600; ++wait) {
        const std::string holder = vfield::test::readTextFile(folder + "/.vfield-lock");
        const std::string pid = vfield::test::readTextFile(pidFile);
        if (!pid.empty() && holder.find("pid " + std::to_string(std::stoi(pid)) + " ") != std::string::npos)
            return std::stoi(pid);
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    FAIL("the background vfield never took the lock of " << folder);
    return -1;
}

void killAndWait(pid_t pid)
{
    ::kill(pid, SIGKILL);
    while (::kill(pid, 0) == 0) std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

} // namespace

TEST_CASE("cli: one writer per folder: a second simulate or render is refused at once naming the holder; kill -9 frees it",
          "[cli][lock]")
{
    const std::string dir = vfield::test::scratchDir("cli-lock");
    std::ofstream(dir + "/s.json") << R"({"version": 1, "frames": {"start": 1, "end": 400, "fps": 24},
      "objects": [{"name": "ground", "mesh": {"box": {"min": [-20, -2, -20], "max": [20, 0, 20]}}}],
      "clouds": [{"count": 20000, "center": [0, 6, 0], "radius": 4}],
      "render": {"resolution": [64, 36], "samplesPerPixel": 1}})";
    const pid_t first = startHolding("simulate " + dir + "/s.json -o " + dir + "/sim", dir + "/sim", dir);

    // The issue's second run: another seed, a few frames, into the same folder.
    const auto start = std::chrono::steady_clock::now();
    const Run second = runVfieldCli("simulate " + dir + "/s.json -o " + dir + "/sim --set /clouds/0/seed=99 --frames 1-5", dir);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    CHECK(second.exitCode == 1);
    CHECK(lineCount(second.err) == 1);
    CHECK(second.err.rfind("vfield simulate: " + dir + "/sim: another vfield is writing here (vfield simulate, pid " +
                               std::to_string(first) + " on ",
                           0) == 0);
    CHECK(seconds < 10.0); // refused at once, not after a simulation

    // Killed once it has written frames (on a busy machine it may still be
    // preparing them now), its lock is gone with it: the next run resumes where it stopped.
    for (int wait = 0; wait < 600 && !std::filesystem::exists(dir + "/sim/density.0002.vdb"); ++wait)
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    killAndWait(first);
    const Run third = runVfieldCli("simulate " + dir + "/s.json -o " + dir + "/sim --frames 1-12", dir);
    INFO(third.err);
    CHECK(third.exitCode == 0);
    CHECK(third.err.find("resumed after frame") != std::string::npos);

    // A render holds its output folder the same way, and --wait waits for it.
    const pid_t rendering = startHolding("render " + dir + "/s.json --sim " + dir + "/sim -o " + dir +
                                             "/img --frames 1-12 --resolution 480x270 --spp 16",
                                         dir + "/img", dir);
    const Run refused = runVfieldCli("render " + dir + "/s.json --sim " + dir + "/sim -o " + dir + "/img --frames 1-2", dir);
    CHECK(refused.exitCode == 1);
    CHECK(refused.err.find(dir + "/img: another vfield is writing here (vfield render, pid " + std::to_string(rendering)) !=
          std::string::npos);
    const Run waited = runVfieldCli("render " + dir + "/s.json --sim " + dir + "/sim -o " + dir +
                                        "/img --frames 1-2 --resolution 480x270 --spp 16 --wait",
                                    dir);
    CHECK(waited.exitCode == 0);
    CHECK(waited.err.find(dir + "/img: waiting for vfield render, pid " + std::to_string(rendering)) != std::string::npos);
    CHECK(waited.err.find("skipped 2 already complete") != std::string::npos); // the holder rendered them meanwhile
}

TEST_CASE("cli: render --backend povray and both write their images, and --keep-scene keeps POV-Ray's files", "[cli][povray]")
{
    const std::string dir = vfield::test::scratchDir("cli-render-povray");
    std::ofstream(dir + "/s.json") << R"({"version": 1, "frames": {"start": 1, "end": 2, "fps": 24},
      "objects": [{"name": "ground", "mesh": {"box": {"min": [-20, -2, -20], "max": [20, 0, 20]}}}],
      "clouds": [{"count": 300, "center": [0, 6, 0], "radius": 2}],
      "camera": {"position": [0, 10, 40], "lookAt": [0, 2, 0]}, "render": {"resolution": [48, 27], "samplesPerPixel": 1}})";
    REQUIRE(runVfieldCli("simulate " + dir + "/s.json -o " + dir + "/sim -q", dir).exitCode == 0);

    const Run pov = runVfieldCli("render " + dir + "/s.json --sim " + dir + "/sim -o " + dir + "/pov --backend povray -q", dir);
    INFO(pov.err);
    REQUIRE(pov.exitCode == 0);
    for (const char* frame : {"/pov/frame.0001.png", "/pov/frame.0002.png"}) CHECK(std::filesystem::exists(dir + frame));
    CHECK_FALSE(std::filesystem::exists(dir + "/pov/povray-scene")); // scene files removed

    const Run both = runVfieldCli(
        "render " + dir + "/s.json --sim " + dir + "/sim -o " + dir + "/both --backend both --keep-scene --frames 2", dir);
    INFO(both.err);
    REQUIRE(both.exitCode == 0);
    CHECK(both.err.find("(povray / embree = ") != std::string::npos);
    CHECK(both.err.find("frame 0/1  (rendering frame 2: 0%)") != std::string::npos); // before its first pixel
    // What POV-Ray cannot draw is said once, before the frames.
    CHECK(both.err.find("warning: povray cannot draw light scattered more than once (render.multipleScattering)") !=
          std::string::npos);
    for (const char* file : {"/both/embree/frame.0002.png", "/both/povray/frame.0002.png", "/both/frame.0002.png",
                             "/both/povray-scene/frame.0002.pov", "/both/povray-scene/meshes.inc",
                             "/both/povray-scene/density.0002.df3", "/both/povray-scene/sky_lit.0002.df3"})
        CHECK(std::filesystem::exists(dir + file));
    OIIO::ImageBuf sideBySide(dir + "/both/frame.0002.png");
    REQUIRE(sideBySide.read());
    CHECK(sideBySide.spec().width == 96);
    CHECK(sideBySide.spec().height == 27);

    const Run exr =
        runVfieldCli("render " + dir + "/s.json --sim " + dir + "/sim -o " + dir + "/exr --backend povray --format exr", dir);
    CHECK(exr.exitCode == 1);
    CHECK(exr.err == "vfield render: the POV-Ray back-end writes png images only\n");
}

TEST_CASE("cli: compare follows idiff's thresholds and exits 0 pass, 1 fail, 2 error", "[cli][compare]")
{
    const std::string dir = vfield::test::scratchDir("cli-compare");
    // A 10x10 grey image, and a copy with one pixel 0.1 brighter and one 0.01.
    const auto write = [&](const std::string& name, float bump, float nudge) {
        OIIO::ImageBuf image(OIIO::ImageSpec(10, 10, 3, OIIO::TypeDesc::FLOAT));
        const float grey[3] = {0.5f, 0.5f, 0.5f};
        OIIO::ImageBufAlgo::fill(image, grey);
        const float bumped[3] = {0.5f + bump, 0.5f, 0.5f}, nudged[3] = {0.5f, 0.5f + nudge, 0.5f};
        image.setpixel(3, 4, bumped, 3);
        image.setpixel(7, 1, nudged, 3);
        REQUIRE(image.write(dir + "/" + name));
    };
    write("a.exr", 0.0f, 0.0f);
    write("b.exr", 0.1f, 0.01f);
    const auto compare = [&](const std::string& arguments) { return runVfieldCli("compare " + arguments, dir); };

    const Run same = compare(dir + "/a.exr " + dir + "/a.exr");
    CHECK(same.exitCode == 0);
    CHECK(same.out.find("PASS") != std::string::npos);
    const Run differ = compare(dir + "/a.exr " + dir + "/b.exr --diff " + dir + "/d.png");
    CHECK(differ.exitCode == 1);
    CHECK(differ.out.find("2 pixels (2%) over 1e-06") != std::string::npos);
    CHECK(differ.out.find("Max error = 0.1 @ (3, 4, channel 0)") != std::string::npos);
    CHECK(std::filesystem::exists(dir + "/d.png"));
    // 2 of 100 pixels over 0.005: 2% allowed passes, 1% fails; a hard limit below 0.1 fails.
    CHECK(compare(dir + "/a.exr " + dir + "/b.exr --fail 0.005 --fail-percent 2").exitCode == 0);
    CHECK(compare(dir + "/a.exr " + dir + "/b.exr --fail 0.005 --fail-percent 1").exitCode == 1);
    CHECK(compare(dir + "/a.exr " + dir + "/b.exr --fail 0.05 --fail-percent 1").exitCode == 0);
    CHECK(compare(dir + "/a.exr " + dir + "/b.exr --fail 0.05 --fail-percent 1 --hard-fail 0.09").exitCode == 1);
    const Run warned = compare(dir + "/a.exr " + dir + "/b.exr --fail 0.2 --warn 0.005");
    CHECK(warned.exitCode == 0);
    CHECK(warned.out.find("WARNING") != std::string::npos);

    // --cloud: the cloud's light in a against b, over the pixels a lights
    // above the frame without it (black here): one whole 8x8 block.
    OIIO::ImageBuf black(OIIO::ImageSpec(10, 10, 3, OIIO::TypeDesc::FLOAT));
    OIIO::ImageBufAlgo::zero(black);
    REQUIRE(black.write(dir + "/clear.exr"));
    const std::string light = dir + "/a.exr " + dir + "/b.exr --cloud " + dir + "/clear.exr";
    const Run agrees = compare(light);
    CHECK(agrees.exitCode == 0);
    CHECK(agrees.out.find("100 cloud pixels") != std::string::npos);
    CHECK(agrees.out.find("1 of 1 blocks of 8x8 pixels within 0.15") != std::string::npos);
    CHECK(compare(light + " --mean-tolerance 0").exitCode == 1);
    const Run png = compare(dir + "/a.png " + dir + "/b.exr --cloud " + dir + "/clear.exr");
    CHECK(png.exitCode == 2);
    CHECK(png.err.find(dir + "/a.png: light is compared on linear radiance") != std::string::npos);
    CHECK(lineCount(png.err) == 1);

    const Run missing = compare(dir + "/a.exr " + dir + "/none.exr");
    CHECK(missing.exitCode == 2);
    CHECK(missing.err.rfind("vfield compare: " + dir + "/none.exr: cannot read the image", 0) == 0);
    CHECK(lineCount(missing.err) == 1);

    // VDB files: voxel by voxel within a tolerance.
    openvdb::initialize();
    const auto grid = [](float value) {
        openvdb::FloatGrid::Ptr g = openvdb::FloatGrid::create(0.0f);
        g->setName("density");
        g->tree().setValue(openvdb::Coord(1, 2, 3), 1.0f);
        g->tree().setValue(openvdb::Coord(4, 5, 6), value);
        return g;
    };
    vfield::writeVdb(dir + "/a.vdb", {grid(2.0f)});
    vfield::writeVdb(dir + "/b.vdb", {grid(2.001f)});
    const Run vdbDiffer = compare(dir + "/a.vdb " + dir + "/b.vdb");
    CHECK(vdbDiffer.exitCode == 1);
    CHECK(vdbDiffer.out.find("density (float): 1 of 2 voxels differ") != std::string::npos);
    CHECK(compare(dir + "/a.vdb " + dir + "/b.vdb --tolerance 0.01").exitCode == 0);
    CHECK(compare(dir + "/a.vdb " + dir + "/a.exr").exitCode == 2);
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

TEST_CASE("cli: tracks.json's matrix places the object-space export where --frame places it", "[cli]")
{
    // The canyon's airplane is scaled 0.7: without the scale in tracks.json a
    // host placed the unscaled export 1.43 times too large.
    const std::string dir = vfield::test::scratchDir("cli-tracks-matrix");
    const std::string scene = std::string(VFIELD_SCENES_DIR) + "/canyon_flythrough.json";
    REQUIRE(runVfieldCli("simulate " + scene + " -o " + dir + "/sim --frames 1-3 -q", dir).exitCode == 0);
    REQUIRE(runVfieldCli("export-mesh " + scene + " --object airplane -o " + dir + "/object.obj", dir).exitCode == 0);
    REQUIRE(
        runVfieldCli("export-mesh " + scene + " --object airplane --frame 3 --sim " + dir + "/sim -o " + dir + "/world.obj", dir)
            .exitCode == 0);
    const nlohmann::json tracks = nlohmann::json::parse(vfield::test::readTextFile(dir + "/sim/tracks.json"));
    CHECK(tracks.at("convention").get<std::string>().find("for column vectors") != std::string::npos);
    const nlohmann::json& entry = tracks.at("objects").at("airplane").at(2);
    REQUIRE(entry.at("frame") == 3);
    CHECK(entry.at("scale").get<double>() == Approx(0.7));
    const std::vector<double> m = entry.at("matrix").get<std::vector<double>>();
    REQUIRE(m.size() == 16);
    CHECK(m[12] == 0.0);
    CHECK(m[15] == 1.0);

    const vfield::TriangleMesh object = vfield::loadMesh(dir + "/object.obj"), world = vfield::loadMesh(dir + "/world.obj");
    REQUIRE(object.points.size() == world.points.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < object.points.size(); ++i) {
        const vfield::Vec3d p(object.points[i]);
        vfield::Vec3d placed;
        for (int row = 0; row < 3; ++row)
            placed[row] = m[4 * row] * p[0] + m[4 * row + 1] * p[1] + m[4 * row + 2] * p[2] + m[4 * row + 3];
        worst = std::max(worst, (placed - vfield::Vec3d(world.points[i])).length());
    }
    CHECK(worst < 1e-3); // the meshes hold float points, some hundreds of units from the origin
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

TEST_CASE("cli: silhouette measures the outline of what a frame brightens against its clear twin", "[cli]")
{
    const std::string dir = vfield::test::scratchDir("cli-silhouette");
    // A dark 256x256 ground, and the same with a white disk on it and a dark
    // shadow beside it: the shadow darkens, so only the disk is cloud.
    const auto write = [&](const std::string& name, bool cloud, int width) {
        OIIO::ImageBuf image(OIIO::ImageSpec(width, 256, 3, OIIO::TypeDesc::UINT8));
        const float ground[3] = {0.3f, 0.4f, 0.2f}, white[3] = {0.9f, 0.9f, 0.9f}, shadow[3] = {0.1f, 0.1f, 0.1f};
        OIIO::ImageBufAlgo::fill(image, ground);
        if (cloud)
            for (int y = 0; y < 256; ++y)
                for (int x = 0; x < width; ++x) {
                    if (std::hypot(x - 100.0, y - 128.0) < 60.0) image.setpixel(x, y, white, 3);
                    else if (x > 180 && x < 250 && y > 20 && y < 60) image.setpixel(x, y, shadow, 3);
                }
        REQUIRE(image.write(dir + "/" + name));
    };
    write("clear.png", false, 256);
    write("cloud.png", true, 256);
    write("wide.png", false, 300);

    checkIsTheDisk(runVfieldCli("silhouette " + dir + "/cloud.png " + dir + "/clear.png", dir));

    const Run mismatched = runVfieldCli("silhouette " + dir + "/cloud.png " + dir + "/wide.png", dir);
    CHECK(mismatched.exitCode != 0);
    CHECK(mismatched.err.find("cloud.png is 256x256 but " + dir + "/wide.png is 300x256") != std::string::npos);
    CHECK(lineCount(mismatched.err) == 1);
}

TEST_CASE("cli: silhouette --opacity measures what a frame's alpha covers, whatever its colour", "[cli]")
{
    const std::string dir = vfield::test::scratchDir("cli-silhouette-opacity");
    // Black sky (alpha 0), a disk of cloud half of it lit and half black: the
    // colour has an edge across the disk, its alpha only the disk's outline.
    OIIO::ImageBuf frame(OIIO::ImageSpec(256, 256, 4, OIIO::TypeDesc::HALF));
    const float lit[4] = {0.9f, 0.9f, 0.9f, 1.0f}, dark[4] = {0.0f, 0.0f, 0.0f, 0.9f};
    for (int y = 0; y < 256; ++y)
        for (int x = 0; x < 256; ++x)
            if (std::hypot(x - 100.0, y - 128.0) < 60.0) frame.setpixel(x, y, y < 128 ? lit : dark, 4);
    REQUIRE(frame.write(dir + "/frame.exr"));
    OIIO::ImageBuf opaque(OIIO::ImageSpec(256, 256, 3, OIIO::TypeDesc::UINT8));
    REQUIRE(opaque.write(dir + "/opaque.png"));

    checkIsTheDisk(runVfieldCli("silhouette --opacity --threshold 0.5 " + dir + "/frame.exr", dir));

    const Run noAlpha = runVfieldCli("silhouette --opacity " + dir + "/opaque.png", dir);
    CHECK(noAlpha.exitCode != 0);
    CHECK(noAlpha.err.find(dir + "/opaque.png has no alpha channel") != std::string::npos);
    CHECK(lineCount(noAlpha.err) == 1);
    const Run neither = runVfieldCli("silhouette " + dir + "/frame.exr", dir);
    CHECK(neither.exitCode == 2);
    CHECK(lineCount(neither.err) == 1);
}

TEST_CASE("cli: a lone cumulus's displaced surface gives its opacity a fractal outline, as real clouds have", "[cli]")
{
    // scenes/features/cumulus.json at 320x180, frame 2, against a transparent
    // sky: the outline of the pixels the cloud covers by more than half, with
    // its displaced detail, with billows and with the particles' smooth
    // density alone. Its opacity is the density's alone, whatever the light.
    const std::string dir = vfield::test::scratchDir("cli-cumulus");
    const std::string scene = std::string(VFIELD_SCENES_DIR) + "/features/cumulus.json";
    const auto dimensionOf = [&](const std::string& name, const std::string& sets) {
        const std::string out = dir + "/" + name;
        REQUIRE(runVfieldCli("run " + scene + " -o " + out +
                                 " --resolution 320x180 --format exr --set /render/transparentSky=true -q " + sets,
                             dir)
                    .exitCode == 0);
        const Run measure = runVfieldCli("silhouette --opacity --threshold 0.5 " + out + "/frame.0002.exr", dir);
        INFO(measure.out);
        const SilhouetteLine line = silhouetteOf(measure);
        CHECK(line.percent > 1.0);
        return line.dimension;
    };
    const double displaced = dimensionOf("displaced", "");
    const double billowed = dimensionOf("billows", "--set '/volume/detail/style=\"billows\"' --set /volume/detail/voxelSize=0.4 "
                                                   "--set /volume/detail/octaves=5 --set /volume/detail/amplitude=2.5 "
                                                   "--set /volume/detail/gain=0.65");
    const double particlesAlone = dimensionOf("plain", "--set /volume/detail/voxelSize=0");
    // Measured 1.312, 1.059 and 1.017; displaced with the detail's seeds 2,
    // 3 and 4: 1.329, 1.326 and 1.266 (the coarsest lumps are few, and the
    // outline's largest boxes follow them). Real clouds' outlines measure
    // 1.33 to 1.35 (Lovejoy 1982); the issue asks 1.25 of the showcases.
    CHECK(displaced >= 1.25);
    CHECK(billowed >= particlesAlone + 0.03);
}
