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
