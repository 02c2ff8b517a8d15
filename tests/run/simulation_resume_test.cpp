// A simulation folder resumes to the same result as an uninterrupted run, is
// simulated afresh after an edit, and gives the same grids for any thread count.

#include "sim_test_scenes.h"
#include "test_meshes.h"

#include <vfield/core/atomic_file.h>
#include <vfield/core/vdb_file.h>
#include <vfield/folder/sim_folder.h>
#include <vfield/render/camera.h>
#include <vfield/run/run_metrics.h>
#include <vfield/run/simulation_run.h>
#include <vfield/scene/inputs_hash.h>
#include <vfield/sim/clearance.h>
#include <vfield/sim/simulator.h>

#include <catch2/catch.hpp>

#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <sstream>

#include <nlohmann/json.hpp>

using namespace vfield;

TEST_CASE("simulator: the same scene gives the same grids for 1 and 2 threads", "[sim][determinism]")
{
    const Scene scene = test::showcaseAtTestResolution("cloud_over_terrain.json", 3000, 30);
    const std::string one = test::scratchDir("threads-1"), two = test::scratchDir("threads-2");
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        simulateScene(scene, one);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        simulateScene(scene, two);
    }
    for (const std::string name : {"field.vdb", "density.0030.vdb", "particles.0030.vdb", "density.0011.vdb"}) {
        const openvdb::GridPtrVec a = readVdb(one + "/" + name), b = readVdb(two + "/" + name);
        REQUIRE(a.size() == b.size());
        for (std::size_t i = 0; i < a.size(); ++i) {
            INFO(name << " grid " << a[i]->getName());
            CHECK(gridChecksum(*a[i]) == gridChecksum(*b[i]));
        }
    }
}

TEST_CASE("simulator: a killed run resumes and ends as an uninterrupted one", "[sim][resume]")
{
    Scene scene = test::showcaseAtTestResolution("cloud_over_terrain.json", 2000, 24);
    scene.simulation.solver.restPeriod = 6; // both rests reset before and after the kill
    const std::string whole = test::scratchDir("resume-whole"), killed = test::scratchDir("resume-killed");
    simulateScene(scene, whole);

    // "Kill" the run after frame 10: the progress callback throws out of it.
    SimulateOptions stopAt10;
    stopAt10.progress = [](const FrameProgress& p) {
        if (p.frame == 10) throw std::runtime_error("killed");
    };
    CHECK_THROWS_WITH(simulateScene(scene, killed, stopAt10), "killed");
    CHECK(std::filesystem::exists(killed + "/density.0010.vdb"));
    CHECK_FALSE(std::filesystem::exists(killed + "/density.0011.vdb"));

    const SimulateSummary resumed = simulateScene(scene, killed);
    CHECK(resumed.resumedAfterFrame == 10);
    CHECK(resumed.frames.size() == 24);
    for (const std::string name : {"density.0024.vdb", "particles.0024.vdb", "density.0011.vdb"}) {
        const openvdb::GridPtrVec a = readVdb(whole + "/" + name), b = readVdb(killed + "/" + name);
        for (std::size_t i = 0; i < a.size(); ++i) CHECK(gridChecksum(*a[i]) == gridChecksum(*b[i]));
    }
    // No temporary files are left behind.
    for (const auto& entry : std::filesystem::directory_iterator(killed))
        CHECK(entry.path().filename().string().find(".tmp-") == std::string::npos);
}

TEST_CASE("simulator: a run resumed from a state saved frames before its last keeps the frames written after it", "[sim][resume]")
{
    // Saving the state costs as much as the particles' bytes, so a large run
    // saves it only now and then: here, a folder whose state is of frame 10
    // while frames 11 to 16 were written after it.
    const Scene scene = test::showcaseAtTestResolution("cloud_over_terrain.json", 2000, 16);
    const std::string dir = test::scratchDir("resume-checkpoint");
    simulateScene(scene, dir, SimulateOptions::writing(1, 10));
    const std::string stateAt10 = test::readTextFile(dir + "/state.bin");
    simulateScene(scene, dir);
    const std::vector<FrameRecord> written = SimFolder(dir).readStats().frames;
    writeTextAtomically(dir + "/state.bin", stateAt10);

    const SimulateSummary resumed = simulateScene(scene, dir);
    CHECK(resumed.resumedAfterFrame == 16);
    CHECK(resumed.frames.size() == 16);
    // Frames 11 to 16 were stepped through, not written again: a rewritten
    // OpenVDB file has a new random id, so its recorded hash would change.
    const std::vector<FrameRecord> after = SimFolder(dir).readStats().frames;
    REQUIRE(after.size() == written.size());
    for (std::size_t i = 0; i < after.size(); ++i) {
        INFO("frame " << after[i].frame);
        REQUIRE(after[i].files);
        CHECK(after[i].files->density.hash == written[i].files->density.hash);
        CHECK(after[i].files->particles.hash == written[i].files->particles.hash);
    }
    CHECK(SimFolder(dir).readRunState().records.size() == 16);
}

TEST_CASE("simulator: a run tells when the folder holds every frame, also when an earlier run had written them all",
          "[sim][resume]")
{
    // `vfield run` shows the simulation's state beside the render's: a rerun
    // that finds every frame written reports no frame, and showed
    // "preparing" to its end.
    const Scene scene = test::showcaseAtTestResolution("cloud_over_terrain.json", 100, 4);
    const std::string dir = test::scratchDir("finished");
    std::vector<int> finished;
    int framesReported = 0;
    SimulateOptions options;
    options.finished = [&](int lastFrame) { finished.push_back(lastFrame); };
    options.progress = [&](const FrameProgress&) { ++framesReported; };
    simulateScene(scene, dir, options);
    CHECK(finished == std::vector<int>{4});
    CHECK(framesReported == 4);
    simulateScene(scene, dir, options);
    CHECK(finished == std::vector<int>{4, 4});
    CHECK(framesReported == 4);
}

TEST_CASE("simulator: an output folder of another scene file is refused", "[sim][resume]")
{
    const std::string dir = test::scratchDir("other-scene");
    const Scene scene = test::showcaseAtTestResolution("cloud_over_terrain.json", 100, 2);
    simulateScene(scene, dir);
    Scene other = scene;
    other.path = dir + "/elsewhere.json";
    CHECK_THROWS_WITH(simulateScene(other, dir), Catch::Contains("holds a simulation of another scene"));
}

TEST_CASE("simulator: an edited scene is simulated afresh, leaving no stale frame", "[sim][resume]")
{
    const std::string dir = test::scratchDir("edited-scene");
    simulateScene(test::showcaseAtTestResolution("cloud_over_terrain.json", 100, 3), dir);
    REQUIRE(std::filesystem::exists(dir + "/density.0003.vdb"));
    const SimulateSummary edited = simulateScene(test::showcaseAtTestResolution("cloud_over_terrain.json", 101, 2), dir);
    CHECK(edited.restartedStale);
    CHECK(edited.resumedAfterFrame == -1);
    CHECK(edited.frames.size() == 2);
    CHECK(edited.frames.back().alive == 101);
    CHECK_FALSE(std::filesystem::exists(dir + "/density.0003.vdb"));
    // Every key that changes where particles start counts, the cloud's billow too.
    Scene billowed = test::showcaseAtTestResolution("cloud_over_terrain.json", 101, 2);
    billowed.simulation.clouds[0].billow = 0.3;
    CHECK(simulateScene(billowed, dir).restartedStale);
    // And so does every key that changes the rest positions written.
    billowed.simulation.solver.restPeriod = 2;
    CHECK(simulateScene(billowed, dir).restartedStale);
}

TEST_CASE("simulator: editing how a scene looks keeps its simulation resumable", "[sim][resume]")
{
    const auto hash = [](const std::string& text) {
        const Scene scene = parseScene(text, "a.json");
        return simulationInputsHash(scene.simulation, scene.volume);
    };
    const std::string text = R"({"version": 1, "objects": [], "camera": {"fovDegrees": 30}})";
    const std::string other = R"({"version": 1,   "objects": [], "camera": {"fovDegrees": 60}, "sun": {"intensity": 2}})";
    CHECK(hash(text) == hash(other));
    CHECK(hash(text) != hash(R"({"version": 1, "objects": [], "seed": 2})"));
}

TEST_CASE("simulator: an edited mesh file is simulated afresh", "[sim][resume]")
{
    // The scene text stays the same; only the airplane's OBJ changes, scaled by 1.6.
    const std::string dir = test::scratchDir("edited-mesh");
    std::filesystem::create_directories(dir + "/scene/meshes");
    std::filesystem::copy_file(std::string(VFIELD_SCENES_DIR) + "/canyon_flythrough.json", dir + "/scene/canyon.json",
                               std::filesystem::copy_options::overwrite_existing);
    const std::string mesh = dir + "/scene/meshes/airplane.obj";
    std::filesystem::copy_file(std::string(VFIELD_SCENES_DIR) + "/meshes/airplane.obj", mesh,
                               std::filesystem::copy_options::overwrite_existing);
    const auto canyon = [&] {
        nlohmann::json json = nlohmann::json::parse(test::readTextFile(dir + "/scene/canyon.json"));
        json["frames"]["end"] = json["frames"]["start"].get<int>() + 2;
        return parseScene(json.dump(), dir + "/scene/canyon.json");
    };
    const std::string sim = dir + "/sim";
    simulateScene(canyon(), sim);
    const std::string statsBefore = test::readTextFile(sim + "/stats.json");

    std::istringstream original(test::readTextFile(mesh));
    std::ostringstream scaled;
    for (std::string line; std::getline(original, line);) {
        if (line.rfind("v ", 0) == 0) {
            std::istringstream v(line.substr(2));
            double x, y, z;
            v >> x >> y >> z;
            scaled << "v " << 1.6 * x << ' ' << 1.6 * y << ' ' << 1.6 * z << '\n';
        } else {
            scaled << line << '\n';
        }
    }
    std::ofstream(mesh) << scaled.str();

    const SimulateSummary again = simulateScene(canyon(), sim);
    CHECK(again.restartedStale);
    CHECK(again.resumedAfterFrame == -1);
    CHECK(test::readTextFile(sim + "/stats.json") != statsBefore);
}

namespace {

/// Every frame file of a and b holds the same grids (whatever the files' random ids).
void requireSameFrames(const std::string& a, const std::string& b, int frames)
{
    for (int f = 1; f <= frames; ++f)
        for (const char* kind : {"density", "particles"}) {
            char name[40];
            std::snprintf(name, sizeof name, "/%s.%04d.vdb", kind, f);
            const openvdb::GridPtrVec x = readVdb(a + name), y = readVdb(b + name);
            REQUIRE(x.size() == y.size());
            for (std::size_t i = 0; i < x.size(); ++i) {
                INFO(name << " grid " << x[i]->getName());
                CHECK(gridChecksum(*x[i]) == gridChecksum(*y[i]));
            }
        }
}

} // namespace

TEST_CASE("simulator: a frame missing, made by another simulation or damaged is simulated again from the frame before it",
          "[sim][resume]")
{
    const Scene scene = test::showcaseAtTestResolution("cloud_over_terrain.json", 2000, 10);
    Scene other = scene;
    other.simulation.clouds[0].seed = 99;
    const std::string whole = test::scratchDir("recheck-whole"), dir = test::scratchDir("recheck"),
                      foreign = test::scratchDir("recheck-other");
    simulateScene(scene, whole);
    simulateScene(other, foreign);
    simulateScene(scene, dir);
    const SimFolder folder(dir);

    // Another simulation's frame: its inputs hash, in the file's metadata, differs.
    std::filesystem::copy_file(SimFolder(foreign).densityFile(6), folder.densityFile(6),
                               std::filesystem::copy_options::overwrite_existing);
    SimulateSummary summary = simulateScene(scene, dir);
    CHECK(summary.resimulatedFrom == 6);
    CHECK_THAT(summary.resimulatedBecause, Catch::Contains("foreign") && Catch::Contains("another simulation"));
    requireSameFrames(whole, dir, 10);

    // A missing file.
    std::filesystem::remove(folder.particlesFile(4));
    summary = simulateScene(scene, dir);
    CHECK(summary.resimulatedFrom == 4);
    CHECK_THAT(summary.resimulatedBecause, Catch::StartsWith("missing"));
    requireSameFrames(whole, dir, 10);

    // Bytes changed in place, the size kept: only the recorded hash tells.
    {
        std::fstream file(folder.densityFile(8), std::ios::in | std::ios::out | std::ios::binary);
        file.seekp(-100, std::ios::end);
        file.put('\x5a');
    }
    summary = simulateScene(scene, dir);
    CHECK(summary.resimulatedFrom == 8);
    CHECK_THAT(summary.resimulatedBecause, Catch::Contains("corrupt") && Catch::Contains("its bytes differ"));
    requireSameFrames(whole, dir, 10);

    // All as written: nothing to do.
    summary = simulateScene(scene, dir);
    CHECK(summary.resimulatedFrom == -1);
    CHECK(summary.resumedAfterFrame == 10);
}

TEST_CASE("sim folder: frames are stamped with their simulation and written at the scene's precision", "[sim][resume]")
{
    Scene scene = test::showcaseAtTestResolution("cloud_over_terrain.json", 20000, 1);
    const std::string compact = test::scratchDir("precision-compact"), full = test::scratchDir("precision-full");
    simulateScene(scene, compact);
    scene.volume.densityPrecision = scene.volume.velocityPrecision = GridPrecision::Float;
    scene.volume.particlePrecision = ParticlePrecision::Full;
    simulateScene(scene, full);

    const SimFolder small(compact), large(full);
    const openvdb::MetaMap stamp = readVdbMetadata(small.densityFile(1));
    CHECK(stamp.metaValue<std::string>("vfield:inputsHash").size() == 16);
    CHECK(stamp.metaValue<int32_t>("vfield:frame") == 1);

    // The same grids, within a 16-bit float's rounding, in fewer bytes: half
    // the bytes a voxel before compression, which evens them out in part
    // (measured 0.84 of the bytes with the showcase's displaced detail).
    const openvdb::FloatGrid::Ptr a = small.readDensity(1), b = large.readDensity(1);
    CHECK(a->saveFloatAsHalf());
    CHECK_FALSE(b->saveFloatAsHalf());
    CHECK(a->activeVoxelCount() == b->activeVoxelCount());
    double worst = 0.0;
    auto other = b->getConstAccessor();
    for (auto it = a->cbeginValueOn(); it; ++it) {
        const double exact = other.getValue(it.getCoord());
        worst = std::max(worst, std::abs(*it - exact) / std::max(exact, 1e-3));
    }
    CHECK(worst <= 1.0 / 2048.0);
    const auto bytes = [](const std::string& path) { return double(std::filesystem::file_size(path)); };
    INFO("density " << bytes(small.densityFile(1)) << " against " << bytes(large.densityFile(1)) << " bytes, particles "
                    << bytes(small.particlesFile(1)) << " against " << bytes(large.particlesFile(1)));
    CHECK(bytes(small.densityFile(1)) < 0.9 * bytes(large.densityFile(1)));
    CHECK(bytes(small.particlesFile(1)) < 0.6 * bytes(large.particlesFile(1)));
}

TEST_CASE("sim folder: stats.json says where each frame's time went, and the run sums it", "[sim]")
{
    const Scene scene = test::showcaseAtTestResolution("cloud_over_terrain.json", 4000, 3);
    const std::string dir = test::scratchDir("stage-seconds");
    const SimulateSummary summary = simulateScene(scene, dir);
    const StatsFile stats = SimFolder(dir).readStats();
    REQUIRE(stats.frames.size() == 3);
    StageSeconds sum;
    for (const FrameRecord& r : stats.frames) {
        const StageSeconds& s = r.stages;
        INFO("frame " << r.frame << ": advection " << s.advection << ", clearance " << s.clearance << ", splat " << s.splat
                      << ", detail " << s.detail << ", write " << s.write << " of " << r.seconds);
        CHECK(s.advection >= 0.0);
        CHECK(s.clearance > 0.0);
        CHECK(s.splat > 0.0);
        CHECK(s.detail > 0.0); // the showcase's density has noise detail
        CHECK(s.write > 0.0);
        // The stages are parts of the frame's time: they add up to it.
        const double parts = s.advection + s.clearance + s.splat + s.detail + s.write;
        CHECK(parts <= r.seconds * 1.0001 + 1e-6);
        CHECK(parts >= 0.8 * r.seconds);
        sum += s;
    }
    CHECK(summary.stages.splat == Approx(sum.splat));
    CHECK(summary.stages.write == Approx(sum.write));
    CHECK(summary.stages.advection == Approx(sum.advection).margin(1e-9));
}

TEST_CASE("simulator: a state restored before every frame moves every particle as one run does", "[sim][resume]")
{
    // A restored simulator has none of the bounds a run carries from frame
    // to frame (each particle's distance to static surfaces): they may spare
    // reads, never change a step. Particles thrown at a static box with a
    // weak field, so that many touch it.
    const std::string text = R"({"version": 1, "frames": {"start": 1, "end": 30, "fps": 24}, "seed": 1,
      "objects": [{"name": "box", "mesh": {"box": {"min": [-2, -2, -2], "max": [2, 2, 2]}},
                   "repulsion": {"strength": 0.05}}],
      "clouds": [{"count": 5000, "shape": "box", "center": [-8, 0, 0], "halfSize": [3, 3, 3], "velocity": [30, 0, 0],
                  "drag": 0}],
      "simulation": {"domain": {"min": [-100, -50, -50], "max": [100, 50, 50]}}})";
    const Scene scene = parseScene(text, "box.json");
    Simulator run(scene.simulation), restored(scene.simulation);
    uint64_t contacts = 0;
    for (int frame = 2; frame <= 30; ++frame) {
        restored.restoreState(run.serializeState());
        run.advanceFrame();
        restored.advanceFrame();
        INFO("frame " << frame);
        REQUIRE(run.particles().id == restored.particles().id);
        CHECK(run.particles().position == restored.particles().position);
        CHECK(run.particles().velocity == restored.particles().velocity);
        CHECK(run.lastStep().substeps == restored.lastStep().substeps);
        CHECK(run.lastStep().contacts == restored.lastStep().contacts);
        contacts += run.lastStep().contacts;
    }
    CHECK(contacts > 100); // bounds were carried up to the surface
}
