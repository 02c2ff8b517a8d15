// Clouds that keep emitting (CloudEmissionSettings): how many, when, where,
// how long they live and fade, the same on any thread count, resumed or sharded.

#include "test_meshes.h"

#include <vfield/core/vdb_file.h>
#include <vfield/scene/scene.h>
#include <vfield/sim/simulator.h>

#include <catch2/catch.hpp>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <fstream>

using namespace vfield;

namespace {

/// A still box of air (no fields, no drag) that one cloud emits into.
Scene emittingScene(const std::string& emission, int frames, const std::string& cloud = "", const std::string& objects = "[]")
{
    return parseScene(R"({"version": 1, "frames": {"start": 1, "end": )" + std::to_string(frames) +
                          R"(, "fps": 24}, "objects": )" + objects + R"(,
        "clouds": [{"name": "c", "count": 1000000, "shape": "box", "halfSize": [5, 5, 5], "drag": 0)" +
                          cloud + R"(, "emission": )" + emission + R"(}],
        "simulation": {"domain": {"min": [-100, -100, -100], "max": [100, 100, 100]}}})",
                      "emitting.json");
}

/// Particles in id order with every attribute, to compare two runs bit for bit.
ParticleSet byId(ParticleSet particles)
{
    particles.sortById();
    return particles;
}

bool identical(const ParticleSet& a, const ParticleSet& b)
{
    return a.id == b.id && a.position == b.position && a.velocity == b.velocity && a.birth == b.birth && a.death == b.death &&
           a.fade == b.fade;
}

} // namespace

TEST_CASE("emission: the particles emitted by each frame are the keyed rate's integral, to within one", "[sim][emission]")
{
    const Scene scene = emittingScene(R"({"rate": {"keys": [[3, 100], [30, 900], [49, 200]], "interpolation": "smooth"},
                                          "start": 2, "end": 55})",
                                      60);
    Simulator sim(scene.simulation);
    const KeyTrack& rate = *scene.simulation.clouds[0].emission->animation.find("rate");
    // The integral by a fine midpoint sum, independently of the emitter's own.
    double integral = 0.0, frame = 2.0;
    const double step = 1.0 / 1024.0;
    for (int f = 2; f <= 60; ++f) {
        sim.advanceFrame();
        for (; frame + step <= std::min(double(f), 55.0) + 1e-12; frame += step)
            integral += keyedValue<double>(rate, frame + 0.5 * step) * step / 24.0;
        INFO("frame " << f);
        CHECK(std::abs(double(sim.particles().size()) - integral) <= 1.0);
    }
    CHECK(integral > 1000.0);
}

TEST_CASE("emission: each particle lives its lifetime within the spread, fading in after its birth and out before its death",
          "[sim][emission]")
{
    const Scene scene = emittingScene(R"({"rate": 240, "lifetime": 1, "lifetimeSpread": 0.25, "fade": 0.25})", 72);
    const CloudEmissionSettings& emission = *scene.simulation.clouds[0].emission;
    Simulator sim(scene.simulation);
    double shortest = 1e9, longest = 0.0;
    for (int f = 2; f <= 72; ++f) {
        sim.advanceFrame();
        const double t = (f - 1) / 24.0;
        const ParticleSet& particles = sim.particles();
        for (std::size_t p = 0; p < particles.size(); ++p) {
            const double birth = particles.birth[p], death = particles.death[p];
            shortest = std::min(shortest, death - birth);
            longest = std::max(longest, death - birth);
            REQUIRE(birth <= t + 1e-6);
            REQUIRE(death > t - 1e-6);
            REQUIRE(particles.fade[p] == Approx(lifeFade(emission, birth, death, t)).margin(1e-6));
        }
        // Past the longest life, births and deaths balance: rate x mean lifetime.
        if (t > 1.3) CHECK(std::abs(double(particles.size()) - 240.0) < 0.15 * 240.0);
    }
    CHECK(shortest >= 0.75 - 1e-6);
    CHECK(longest <= 1.25 + 1e-6);
    CHECK(shortest < 0.8);
    CHECK(longest > 1.2);
    // The fade: nothing at birth or death, whole between, smooth.
    CHECK(lifeFade(emission, 1.0, 2.0, 1.0) == 0.0);
    CHECK(lifeFade(emission, 1.0, 2.0, 1.125) == Approx(0.5));
    CHECK(lifeFade(emission, 1.0, 2.0, 1.5) == 1.0);
    CHECK(lifeFade(emission, 1.0, 2.0, 2.0) == 0.0);
}

TEST_CASE("emission: the cloud's count caps the particles alive at once", "[sim][emission]")
{
    Scene scene = emittingScene(R"({"rate": 1000, "lifetime": 0.5})", 48);
    scene.simulation.clouds[0].count = 50;
    Simulator sim(scene.simulation);
    std::size_t most = 0;
    for (int f = 2; f <= 48; ++f) {
        sim.advanceFrame();
        most = std::max(most, sim.particles().size());
    }
    CHECK(most == 50);
}

TEST_CASE("emission: the same particles on any thread count, resumed, or split among shards", "[sim][emission]")
{
    // Stirred by turbulence so that the particles' paths depend on where each is born.
    Scene scene = emittingScene(R"({"rate": 600, "lifetime": 0.6, "lifetimeSpread": 0.3, "fade": 0.1})", 40,
                                R"(, "billow": 0.4, "velocity": [2, 0, 0])");
    scene.simulation.turbulence.emplace_back();
    const auto run = [&](int threads, int frames) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        auto sim = std::make_unique<Simulator>(scene.simulation);
        for (int f = 2; f <= frames; ++f) sim->advanceFrame();
        return sim;
    };
    const ParticleSet whole = byId(run(2, 40)->particles());
    REQUIRE(whole.size() > 100);
    CHECK(identical(whole, byId(run(1, 40)->particles())));

    // Stopped at frame 17 (between births and deaths) and resumed.
    const std::string state = run(2, 17)->serializeState();
    Simulator resumed(scene.simulation);
    resumed.restoreState(state);
    for (int f = 18; f <= 40; ++f) resumed.advanceFrame();
    CHECK(identical(whole, byId(resumed.particles())));

    // Two shards, each keeping the ids of one parity, together are the whole.
    ParticleSet shards;
    for (uint32_t part = 0; part < 2; ++part) {
        Simulator shard(scene.simulation);
        shard.keepParticles([part](uint32_t id) { return id % 2 == part; });
        for (int f = 2; f <= 40; ++f) shard.advanceFrame();
        CHECK(!shard.particles().id.empty());
        shards.append(shard.particles());
    }
    CHECK(identical(whole, byId(shards)));
}

TEST_CASE("emission: from an object's surface, from inside its closed mesh, and from a VDB in proportion to its density",
          "[sim][emission]")
{
    const std::string block = R"([{"name": "block", "mesh": {"box": {"min": [-2, -1, -3], "max": [2, 1, 3]}},
                                   "transform": {"translate": [10, 0, 0]}, "repulsion": false}])";
    // How far beyond the block's faces (<= 0: inside) each particle born in the first frame stands.
    const auto bornFrom = [&](const std::string& source) {
        Simulator sim(
            emittingScene(R"({"rate": 2400, "from": ")" + source + R"(", "object": "block"})", 3, "", block).simulation);
        sim.advanceFrame();
        std::vector<double> beyondFaces;
        for (const Vec3f& p : sim.particles().position) {
            const Vec3d q = Vec3d(p) - Vec3d(10, 0, 0);
            beyondFaces.push_back(std::max({std::abs(q[0]) - 2.0, std::abs(q[1]) - 1.0, std::abs(q[2]) - 3.0}));
        }
        return beyondFaces;
    };
    const std::vector<double> onSurface = bornFrom("surface"), inside = bornFrom("inside");
    REQUIRE(onSurface.size() > 50);
    REQUIRE(inside.size() > 50);
    for (const double beyond : onSurface) CHECK(std::abs(beyond) < 1e-4);
    for (const double beyond : inside) CHECK(beyond <= 0.0);
    {
        // Two blocks of voxels, density 1 and 3, beside voxels below the threshold.
        openvdb::initialize();
        openvdb::FloatGrid::Ptr density = openvdb::FloatGrid::create(0.0f);
        density->setName("density");
        density->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
        density->tree().fill(openvdb::CoordBBox(openvdb::Coord(0, 0, 0), openvdb::Coord(7, 7, 7)), 1.0f);
        density->tree().fill(openvdb::CoordBBox(openvdb::Coord(20, 0, 0), openvdb::Coord(27, 7, 7)), 3.0f);
        density->tree().fill(openvdb::CoordBBox(openvdb::Coord(40, 0, 0), openvdb::Coord(47, 7, 7)), 0.05f);
        const std::string file = test::scratchDir("emission-volume") + "/source.vdb";
        writeVdb(file, {density});
        Simulator sim(
            emittingScene(R"({"rate": 48000, "from": "volume", "file": ")" + file + R"(", "threshold": 0.1})", 3).simulation);
        sim.advanceFrame(); // every particle born in this frame
        const std::vector<Vec3f>& born = sim.particles().position;
        REQUIRE(born.size() > 1000);
        int low = 0, high = 0;
        for (const Vec3f& p : born) {
            CHECK(p[1] >= -0.25);
            CHECK(p[1] <= 3.75);
            if (p[0] >= -0.25 && p[0] <= 3.75) ++low;
            else if (p[0] >= 9.75 && p[0] <= 13.75) ++high;
        }
        CHECK(low + high == int(born.size()));
        CHECK(double(high) / double(low) == Approx(3.0).epsilon(0.15));
    }
}

TEST_CASE("emission: an emitter naming no object, or emitting from inside an open one, is refused", "[sim][emission]")
{
    CHECK_THROWS_WITH(emittingScene(R"({"from": "surface", "object": "nothing"})", 3),
                      Catch::Contains("/clouds/0/emission/object: no object is named \"nothing\""));
    CHECK_THROWS_WITH(emittingScene(R"({"lifetime": 1, "lifetimeSpread": 2})", 3),
                      Catch::Contains("/clouds/0/emission/lifetimeSpread: the spread must be less than the lifetime"));
    CHECK_THROWS_WITH(emittingScene(R"({"from": "shape", "object": "a"})", 3),
                      Catch::Contains("/clouds/0/emission/object: \"object\" applies to"));
    const std::string sheet = test::scratchDir("emission-open") + "/sheet.obj";
    std::ofstream(sheet) << "v 0 0 0\nv 4 0 0\nv 4 0 4\nv 0 0 4\nf 1 2 3\nf 1 3 4\n";
    const std::string open = R"([{"name": "sheet", "mesh": {"file": ")" + sheet + R"("}, "repulsion": false}])";
    CHECK_THROWS_WITH(Simulator(emittingScene(R"({"from": "inside", "object": "sheet"})", 3, "", open).simulation),
                      Catch::Contains("clouds/0/emission/object: \"sheet\" is not closed"));
}
