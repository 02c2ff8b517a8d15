// A simulation split into shards (the objects once, the particles by id, a
// merge per frame) writes the frames one run writes, resumes per part, and
// refuses parts that do not fit together.

#include "sim_test_scenes.h"
#include "test_meshes.h"

#include <vfield/core/error.h>
#include <vfield/core/vdb_file.h>
#include <vfield/image/grid_compare.h>
#include <vfield/run/shard_merge.h>
#include <vfield/run/simulation_run.h>
#include <vfield/volume/particle_grid.h>

#include <catch2/catch.hpp>

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

using namespace vfield;

namespace {

/// The airplane through its cloud, small: 3000 particles, 12 frames, grids
/// in full floats so that they compare to float rounding.
Scene shardedTestScene()
{
    Scene scene = test::showcaseAtTestResolution("plane_through_cloud.json", 3000, 12);
    scene.volume.densityPrecision = GridPrecision::Float;
    scene.volume.velocityPrecision = GridPrecision::Float;
    scene.volume.particlePrecision = ParticlePrecision::Full;
    return scene;
}

/// Every part of a sharded simulation in turn, then the merge.
SimulateSummary simulateSharded(const Scene& scene, const std::string& out, int shards)
{
    SimulateOptions options;
    options.part = ShardPart::objects();
    simulateScene(scene, out, options);
    for (int i = 0; i < shards; ++i) {
        options.part = ShardPart{i, shards};
        simulateScene(scene, out, options);
    }
    return mergeShards(scene, out, shards);
}

/// The frame's density and particle files of two folders hold the same grids, bit for bit.
void checkSameGrids(const std::string& first, const std::string& second, int frame)
{
    const SimFolder a(first), b(second);
    for (const auto& [x, y] :
         {std::pair{a.densityFile(frame), b.densityFile(frame)}, {a.particlesFile(frame), b.particlesFile(frame)}}) {
        const openvdb::GridPtrVec gridsX = readVdb(x), gridsY = readVdb(y);
        REQUIRE(gridsX.size() == gridsY.size());
        for (std::size_t i = 0; i < gridsX.size(); ++i) {
            INFO(x << " grid " << gridsX[i]->getName());
            CHECK(gridChecksum(*gridsX[i]) == gridChecksum(*gridsY[i]));
        }
    }
}

/// The frame's density grids of two folders: the same voxels, values equal
/// but for the order of the sums.
void checkSameDensity(const std::string& first, const std::string& second, int frame)
{
    INFO("frame " << frame);
    const GridComparison grids =
        compareGridFiles(SimFolder(first).densityFile(frame), SimFolder(second).densityFile(frame), 1e-6);
    CHECK(grids.onlyInA.empty());
    CHECK(grids.onlyInB.empty());
    for (const GridDifference& grid : grids.grids) {
        INFO(grid.name << ": " << grid.differing << " of " << grid.voxels << " voxels differ, at most by " << grid.maxDifference);
        CHECK(grid.voxels > 100);
        CHECK(grid.differing == 0);
    }
}

ParticleSet particlesOf(const std::string& path)
{
    for (const openvdb::GridBase::Ptr& grid : readVdb(path))
        if (grid->getName() == "particles") return readParticleGrid(*grid);
    FAIL("no particles in " << path);
    return {};
}

} // namespace

TEST_CASE("sharded simulation: a cloud that keeps emitting merges into the frames of one run", "[sim][shards][emission]")
{
    // The cap cloud's stream, thin and short: births and deaths on every frame.
    Scene scene = test::showcaseAtTestResolution("cap_cloud.json", 400000, 12);
    CloudEmissionSettings& emission = *scene.simulation.clouds[0].emission;
    emission.rate = 1500.0;
    emission.lifetime = 2.0;
    emission.lifetimeSpread = 1.0;
    scene.simulation.solver.preroll = 48;
    emission.start = -47.0;
    scene.volume.condensation.lift = 0.0; // all of it visible, to compare
    scene.volume.densityPrecision = GridPrecision::Float;
    scene.volume.velocityPrecision = GridPrecision::Float;
    scene.volume.particlePrecision = ParticlePrecision::Full;
    const std::string whole = test::scratchDir("shards-emitting-whole"), sharded = test::scratchDir("shards-emitting-two");
    const SimulateSummary one = simulateScene(scene, whole);
    const SimulateSummary merged = simulateSharded(scene, sharded, 2);
    REQUIRE(merged.frames.size() == one.frames.size());
    for (std::size_t f = 0; f < one.frames.size(); ++f) CHECK(merged.frames[f].alive == one.frames[f].alive);
    CHECK(one.frames.back().alive > 2000);
    for (const int frame : {1, 6, 12}) checkSameDensity(whole, sharded, frame);
}

TEST_CASE("sharded simulation: three shards merge into the frames of one run, to float rounding", "[sim][shards]")
{
    const Scene scene = shardedTestScene();
    const std::string whole = test::scratchDir("shards-whole"), sharded = test::scratchDir("shards-three");
    const SimulateSummary one = simulateScene(scene, whole);
    const SimulateSummary merged = simulateSharded(scene, sharded, 3);

    REQUIRE(merged.frames.size() == one.frames.size());
    for (std::size_t f = 0; f < one.frames.size(); ++f) {
        const FrameRecord &a = one.frames[f], &b = merged.frames[f];
        INFO("frame " << a.frame);
        CHECK(b.frame == a.frame);
        CHECK(b.alive == a.alive);
        CHECK(b.removed == a.removed);
        CHECK(b.substeps == a.substeps); // each particle took the same substeps
        CHECK(b.contacts == a.contacts);
        CHECK(b.particleClearance.minimum == a.particleClearance.minimum);
        CHECK(b.particleClearance.penetrations == 0);
        CHECK(b.objectPairs.size() == a.objectPairs.size());
    }
    CHECK(merged.frames.back().alive > 2500); // most of the cloud is there to compare

    for (const int frame : {1, 6, 12}) {
        INFO("frame " << frame);
        const SimFolder a(whole), b(sharded);
        checkSameDensity(whole, sharded, frame);
        // The same particles, each where one run put it (its position within
        // a millionth of the particle grid's voxel, read back from the files).
        const ParticleSet p = particlesOf(a.particlesFile(frame)), q = particlesOf(b.particlesFile(frame));
        REQUIRE(p.size() == q.size());
        CHECK(p.id == q.id);
        double worst = 0.0;
        for (std::size_t i = 0; i < p.size(); ++i) worst = std::max(worst, double((p.position[i] - q.position[i]).length()));
        CHECK(worst < 1e-4);
        CHECK(p.velocity == q.velocity);
    }
    // Renderers and hosts find the merged folder complete.
    CHECK(std::filesystem::exists(SimFolder(sharded).fieldFile()));
    CHECK(std::filesystem::exists(sharded + "/host"));
    CHECK(SimFolder(sharded).readTracks().objects().at("airplane").size() == 12);
}

TEST_CASE("sharded simulation: two shards give the same grids for 1 and 2 threads", "[sim][shards][determinism]")
{
    const Scene scene = shardedTestScene();
    const std::string one = test::scratchDir("shards-threads-1"), two = test::scratchDir("shards-threads-2");
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        simulateSharded(scene, one, 2);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        simulateSharded(scene, two, 2);
    }
    for (const int frame : {1, 12}) checkSameGrids(one, two, frame);
}

TEST_CASE("sharded simulation: a shard and a merge stopped midway resume after their last frame", "[sim][shards][resume]")
{
    const Scene scene = shardedTestScene();
    const std::string straight = test::scratchDir("shards-straight"), stopped = test::scratchDir("shards-stopped");
    simulateSharded(scene, straight, 2);

    SimulateOptions options;
    options.part = ShardPart::objects();
    simulateScene(scene, stopped, options);
    options.part = ShardPart{0, 2};
    simulateScene(scene, stopped, options);
    options.part = ShardPart{1, 2};
    options.lastFrame = 5; // stopped after frame 5
    simulateScene(scene, stopped, options);
    options.lastFrame.reset();
    CHECK(simulateScene(scene, stopped, options).resumedAfterFrame == 5);
    CHECK(mergeShards(scene, stopped, 2, SimulateOptions::writing(1, 7)).resumedAfterFrame == -1);
    const SimulateSummary resumed = mergeShards(scene, stopped, 2);
    CHECK(resumed.resumedAfterFrame == 7);
    CHECK(resumed.frames.size() == 12);

    for (const int frame : {5, 6, 12}) checkSameGrids(straight, stopped, frame);
}

TEST_CASE("sharded simulation: parts that do not fit together are refused, naming the command that makes them",
          "[sim][shards][errors]")
{
    const Scene scene = shardedTestScene();
    const std::string out = test::scratchDir("shards-refused");
    SimulateOptions shard;
    shard.part = ShardPart{0, 2};
    // A shard replays the objects: without their part it cannot start.
    CHECK_THROWS_WITH(simulateScene(scene, out, shard), Catch::Contains("shards/objects") && Catch::Contains("--shard objects"));

    SimulateOptions objects;
    objects.part = ShardPart::objects();
    objects.lastFrame = 6;
    simulateScene(scene, out, objects);
    // Nor beyond the frames the objects' part reached.
    CHECK_THROWS_WITH(simulateScene(scene, out, shard), Catch::Contains("up to frame 6, not 12"));
    shard.lastFrame = 6;
    simulateScene(scene, out, shard);
    // The merge needs every shard, through the frames it merges.
    CHECK_THROWS_WITH(mergeShards(scene, out, 2, SimulateOptions::writing(1, 6)),
                      Catch::Contains("1-of-2") && Catch::Contains("--shard 1/2"));
    CHECK_THROWS_WITH(mergeShards(scene, out, 1, SimulateOptions::writing(1, 6)), Catch::Contains("0-of-1"));
    shard.part = ShardPart{1, 2};
    simulateScene(scene, out, shard);
    mergeShards(scene, out, 2, SimulateOptions::writing(1, 6));
    // A merged folder is no single run's, and the other way round.
    CHECK_THROWS_WITH(simulateScene(scene, out, SimulateOptions::writing(1, 6)),
                      Catch::Contains("merge of a sharded simulation"));
    const std::string single = test::scratchDir("shards-single");
    simulateScene(scene, single, SimulateOptions::writing(1, 2));
    std::filesystem::copy(out + "/shards", single + "/shards", std::filesystem::copy_options::recursive);
    CHECK_THROWS_WITH(mergeShards(scene, single, 2, SimulateOptions::writing(1, 6)), Catch::Contains("run whole"));

    CHECK_THROWS_AS(ShardPart::parse("2/2"), ValueError);
    CHECK_THROWS_AS(ShardPart::parse("1/"), ValueError);
    CHECK(ShardPart::parse("3/8").folder("out") == "out/shards/3-of-8");
}

TEST_CASE("sharded simulation: with displaced detail and condensation, two and three shards give one run's grids, bit "
          "for bit",
          "[sim][shards]")
{
    // The cumulus through the pass, small: its displaced detail and
    // condensation turn any difference in the splat's sums into visible ones.
    Scene scene = test::showcaseAtTestResolution("cloud_over_terrain.json", 4000, 8);
    scene.volume.densityPerParticle *= 50.0; // as dense as the whole cloud of 200,000
    scene.volume.densityPrecision = GridPrecision::Float;
    scene.volume.velocityPrecision = GridPrecision::Float;
    REQUIRE(scene.volume.detail.style == DetailStyle::Displaced);
    REQUIRE(scene.volume.condensation.enabled());
    const std::string whole = test::scratchDir("shards-detail-whole");
    simulateScene(scene, whole);
    for (const int shards : {2, 3}) {
        const std::string sharded = test::scratchDir("shards-detail-" + std::to_string(shards));
        simulateSharded(scene, sharded, shards);
        for (int frame = 1; frame <= 8; ++frame) {
            INFO(shards << " shards, frame " << frame);
            const openvdb::GridPtrVec a = readVdb(SimFolder(whole).densityFile(frame)),
                                      b = readVdb(SimFolder(sharded).densityFile(frame));
            REQUIRE(a.size() == b.size());
            for (std::size_t i = 0; i < a.size(); ++i) {
                INFO(a[i]->getName());
                CHECK(a[i]->activeVoxelCount() > 1000);
                CHECK(gridChecksum(*a[i]) == gridChecksum(*b[i]));
            }
        }
    }
}
