// The simulator's physics, each against an answer computed by hand: free fall
// with drag, terminal velocity, substeps within cfl, fields in boxes, turning
// aircraft, contact, emission and dual rest.

#include "sim_test_scenes.h"
#include "test_meshes.h"

#include <vfield/core/error.h>
#include <vfield/core/vdb_file.h>
#include <vfield/mesh/mesh_io.h>
#include <vfield/render/camera.h>
#include <vfield/run/run_metrics.h>
#include <vfield/run/simulation_run.h>
#include <vfield/scene/inputs_hash.h>
#include <vfield/sim/clearance.h>
#include <vfield/sim/motion.h>
#include <vfield/sim/simulator.h>

#include <catch2/catch.hpp>

#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <sstream>

#include <nlohmann/json.hpp>

using namespace vfield;

namespace {

Vec3d onlyParticle(const Simulator& sim) { return Vec3d(sim.particles().position.at(0)); }

void runFrames(Simulator& sim, int frames)
{
    for (int i = 0; i < frames; ++i) sim.advanceFrame();
}

} // namespace

TEST_CASE("simulator: free fall with drag follows the analytic solution", "[sim]")
{
    // The velocity relaxes exactly under drag; the position moves with the new
    // velocity, first order: its drift is about g t dt / 2, so frames of
    // 1/240 s keep it near 0.3% here (at 24 fps it would be 3%).
    const double g = 9.81, k = 0.5;
    Simulator sim(test::singleParticleScene(R"([{"acceleration": [0, -9.81, 0]}])", 481, k, 240.0).simulation);
    runFrames(sim, 480); // 2 seconds
    const double t = 2.0;
    const double y = -(g / k) * t + (g / (k * k)) * (1 - std::exp(-k * t));
    const double v = -(g / k) * (1 - std::exp(-k * t));
    CHECK(onlyParticle(sim)[1] == Approx(y).epsilon(0.01));
    CHECK(sim.particles().velocity[0][1] == Approx(v).epsilon(1e-6));
    CHECK(std::abs(onlyParticle(sim)[0]) < 1e-8);
}

TEST_CASE("simulator: a drag of 1e4 creeps downwind in a few substeps a frame", "[sim]")
{
    // An explicit step overshoots once drag dt > 1: it would run the cloud upwind
    // and cut frames into a hundred substeps or more. Exactly integrated, the cloud moves
    // at its terminal velocity, wind / drag = 15e-4 units/s.
    Scene scene = test::showcaseAtTestResolution("cloud_over_terrain.json", 500, 4);
    scene.simulation.clouds[0].drag = 1e4;
    Simulator sim(scene.simulation);
    std::map<uint32_t, Vec3f> start; // by id: the simulator reorders particles
    for (std::size_t p = 0; p < sim.particles().size(); ++p) start[sim.particles().id[p]] = sim.particles().position[p];
    for (int frame = 0; frame < 3; ++frame) {
        sim.advanceFrame();
        INFO("frame " << frame + 2);
        CHECK(sim.lastStep().maxSubsteps <= 3);
    }
    double meanDownwind = 0.0, largest = 0.0;
    REQUIRE(sim.particles().size() == start.size());
    for (std::size_t p = 0; p < start.size(); ++p) {
        const Vec3d moved = Vec3d(sim.particles().position[p]) - Vec3d(start.at(sim.particles().id[p]));
        meanDownwind += moved[0] / double(start.size());
        largest = std::max(largest, moved.length());
    }
    CHECK(meanDownwind > 0.0);
    CHECK(largest < 0.01); // 3 frames of 1/24 s at a terminal speed of at most (field + wind) / drag
}

TEST_CASE("simulator: a particle reaches terminal velocity g over drag", "[sim]")
{
    Simulator sim(test::singleParticleScene(R"([{"acceleration": [0, -9.81, 0]}])", 241, 2.0).simulation);
    runFrames(sim, 240); // 10 s = 20 time constants
    CHECK(sim.particles().velocity[0][1] == Approx(-9.81 / 2.0).epsilon(1e-4));
}

TEST_CASE("simulator: substeps keep each move within cfl of the cell around the particle", "[sim]")
{
    // No fields: the step bound is cfl x 1 world unit; a particle at 100 units/s
    // moving 100/24 units a frame takes ceil(4.17 / 0.5) = 9 substeps.
    const std::string text = R"({"version": 1, "frames": {"start": 1, "end": 2, "fps": 24}, "objects": [],
      "clouds": [{"count": 1, "shape": "box", "halfSize": [1e-9, 1e-9, 1e-9], "velocity": [100, 0, 0], "drag": 0}],
      "simulation": {"domain": {"min": [-1000, -1000, -1000], "max": [1000, 1000, 1000]}}})";
    Simulator sim(parseScene(text, "fast.json").simulation);
    sim.advanceFrame();
    CHECK(sim.lastStep().maxSubsteps == 9);
    CHECK(onlyParticle(sim)[0] == Approx(100.0 / 24.0));
}

TEST_CASE("motion: a substep within reach travels no farther, and is the whole remaining time when that fits", "[sim]")
{
    std::mt19937 random(5);
    std::uniform_real_distribution<double> component(-50.0, 50.0), positive(1e-3, 2.0);
    int whole = 0;
    for (int i = 0; i < 100000; ++i) {
        const Vec3d v(component(random), component(random), component(random));
        const Vec3d a(component(random), component(random), component(random));
        const double remaining = 0.1 * positive(random), reach = positive(random),
                     extraSpeed = i % 4 == 0 ? positive(random) : 0.0;
        const double dt = stepWithin(remaining, v, extraSpeed, a, reach);
        INFO("case " << i);
        REQUIRE(dt <= remaining);
        REQUIRE((v.length() + extraSpeed) * dt + a.length() * dt * dt <= reach * (1.0 + 1e-12));
        REQUIRE(dt == Approx(std::min(remaining, stepLimit(v.length() + extraSpeed, a.length(), reach))).epsilon(1e-12));
        if (dt == remaining) ++whole;
    }
    CHECK(whole > 1000); // both ways were taken
}

TEST_CASE("simulator: a billowed cloud is emitted as lumps cut into its shape, its core full", "[sim]")
{
    const auto emitted = [](double billow) {
        const std::string text = R"({"version": 1, "objects": [], "clouds": [{"count": 40000, "shape": "sphere",
          "radius": 10, "center": [0, 50, 0], "billow": )" +
                                 std::to_string(billow) + R"(, "billowSize": 6}]})";
        Simulator sim(parseScene(text, "puffs.json").simulation);
        std::vector<Vec3d> offsets; // from the centre, in radii
        for (const Vec3f& p : sim.particles().position) offsets.push_back((Vec3d(p) - Vec3d(0, 50, 0)) / 10.0);
        return offsets;
    };
    // The outline: the farthest particle in each of 8 x 16 latitude-longitude bins.
    const auto outline = [](const std::vector<Vec3d>& offsets) {
        std::vector<double> farthest(8 * 16, 0.0);
        for (const Vec3d& u : offsets) {
            const double r = u.length();
            const int lat = std::min(7, int((std::acos(std::clamp(u[1] / r, -1.0, 1.0)) / M_PI) * 8));
            const int lon = std::min(15, int((std::atan2(u[2], u[0]) / M_PI + 1.0) * 8));
            farthest[lat * 16 + lon] = std::max(farthest[lat * 16 + lon], r);
        }
        return farthest;
    };
    const auto coreFraction = [](const std::vector<Vec3d>& offsets) {
        return double(std::count_if(offsets.begin(), offsets.end(), [](const Vec3d& u) { return u.length() < 0.3; })) /
               double(offsets.size());
    };
    const std::vector<Vec3d> plain = emitted(0.0), puffs = emitted(0.7);
    for (const Vec3d& u : puffs) REQUIRE(u.length() <= 1.0 + 1e-6);
    const std::vector<double> round = outline(plain), lumpy = outline(puffs);
    // A plain sphere's outline is round; a billowed one comes in to 1 - 0.7 at
    // its deepest creases and reaches the full radius at its puffs.
    CHECK(*std::min_element(round.begin(), round.end()) > 0.95);
    CHECK(*std::min_element(lumpy.begin(), lumpy.end()) < 0.75);
    CHECK(*std::max_element(lumpy.begin(), lumpy.end()) > 0.95);
    // Within 0.3 of the centre every point is kept: the same count fills a
    // smaller volume, so the core holds a larger share of it.
    CHECK(coreFraction(plain) == Approx(0.027).margin(0.004));
    CHECK(coreFraction(puffs) > 1.5 * coreFraction(plain));
}

TEST_CASE("simulator: a fine field far from the cloud leaves its substeps as they were", "[sim]")
{
    // Each particle's substep bound counts the cells of the fields around it,
    // not the finest leaf of any field in the scene: an airplane parked far
    // above the terrain must not multiply every particle's substeps.
    const auto meanSubsteps = [](const Scene& scene) {
        Simulator sim(scene.simulation);
        uint64_t substeps = 0, particleFrames = 0;
        for (int frame = 0; frame < 40; ++frame) {
            sim.advanceFrame();
            substeps += sim.lastStep().substeps;
            particleFrames += sim.particles().size();
        }
        return double(substeps) / double(particleFrames);
    };
    Scene alone = test::showcaseAtTestResolution("cloud_over_terrain.json", 2000, 41);
    Scene withAirplane = alone;
    ObjectSettings airplane;
    airplane.name = "parked airplane";
    airplane.mesh.kind = MeshSettings::Kind::File;
    airplane.mesh.path = std::string(VFIELD_SCENES_DIR) + "/meshes/airplane.obj";
    airplane.transform.translation = Vec3d(60, 70, 80);
    airplane.transform.scale = 0.7;
    airplane.repulsion = RepulsionSettings{};
    airplane.repulsion->field.margin = 3.0;
    airplane.repulsion->field.maxLevel = 5;
    withAirplane.simulation.objects.push_back(airplane);

    const double without = meanSubsteps(alone), with = meanSubsteps(withAirplane);
    INFO("substeps per particle and frame: " << without << " alone, " << with << " with the airplane");
    CHECK(Simulator(withAirplane.simulation).finestCellSize() < 0.5 * Simulator(alone.simulation).finestCellSize());
    CHECK(with == Approx(without).epsilon(0.02));
}

TEST_CASE("simulator: a uniform field acts only inside its box and fades across its soft edge", "[sim]")
{
    UniformFieldSettings field;
    field.acceleration = Vec3d(0, 0, 4);
    field.box = BBoxd(Vec3d(0.0), Vec3d(10.0));
    field.softEdge = 2.0;
    CHECK(field.accelerationAt({5, 5, 5}, 1.0) == Vec3d(0, 0, 4));
    CHECK(field.accelerationAt({11, 5, 5}, 1.0) == Vec3d(0, 0, 2));   // halfway across the edge
    CHECK(field.accelerationAt({12.5, 5, 5}, 1.0) == Vec3d(0, 0, 0)); // beyond it

    // A particle outside a hard-edged box stays at rest.
    Simulator sim(
        test::singleParticleScene(R"([{"acceleration": [5, 0, 0], "box": {"min": [10, -1, -1], "max": [20, 1, 1]}}])", 25, 0.0)
            .simulation);
    runFrames(sim, 24);
    CHECK(onlyParticle(sim).length() < 1e-8);
}

TEST_CASE("simulator: a keyed field's acceleration is read at each substep's own time", "[sim]")
{
    // a(t) = 24 t along x (keys at frames 1 and 241 of 240 fps, linear): after
    // one second the velocity is 12 and the particle has moved 4, exactly as
    // the integral says, not as frames of constant acceleration would have it.
    Simulator sim(
        test::singleParticleScene(R"([{"acceleration": {"keys": [[1, [0, 0, 0]], [241, [24, 0, 0]]]}}])", 241, 0.0, 240.0)
            .simulation);
    runFrames(sim, 240);
    CHECK(sim.particles().velocity[0][0] == Approx(12.0).epsilon(0.01));
    CHECK(onlyParticle(sim)[0] == Approx(4.0).epsilon(0.01));
}

TEST_CASE("simulator: a field that names what it affects moves only those", "[sim]")
{
    // Two boxes and a cloud at rest; the wind pushes only "pushed" and the cloud.
    const std::string text = R"({"version": 1, "frames": {"start": 1, "end": 25, "fps": 24},
      "objects": [{"name": "pushed", "mesh": {"box": {}}, "motion": "dynamic", "repulsion": false},
                  {"name": "left", "mesh": {"box": {}}, "motion": "dynamic", "repulsion": false,
                   "transform": {"translate": [0, 10, 0]}}],
      "clouds": [{"name": "dust", "count": 5, "center": [0, -10, 0], "radius": 1, "drag": 0}],
      "fields": [{"name": "wind", "acceleration": [2, 0, 0], "affects": ["pushed", "dust"]}],
      "simulation": {"domain": {"min": [-100, -100, -100], "max": [100, 100, 100]}}})";
    const Scene scene = parseScene(text, "affects.json");
    Simulator sim(scene.simulation);
    std::map<uint32_t, Vec3d> dustStart;
    for (std::size_t p = 0; p < sim.particles().size(); ++p)
        dustStart[sim.particles().id[p]] = Vec3d(sim.particles().position[p]);
    for (int frame = 0; frame < 24; ++frame) sim.advanceFrame();
    // One second at 2 units/s^2 from rest: one unit along x.
    CHECK(sim.objectStates()[0].pose.translation[0] == Approx(1.0).epsilon(0.05));
    CHECK(sim.objectStates()[1].pose.translation == Vec3d(0, 10, 0));
    for (std::size_t p = 0; p < sim.particles().size(); ++p)
        CHECK(double(sim.particles().position[p][0]) - dustStart[sim.particles().id[p]][0] == Approx(1.0).epsilon(0.05));
}

TEST_CASE("simulator: particles leaving the domain are removed and counted", "[sim]")
{
    const std::string text = R"({"version": 1, "frames": {"start": 1, "end": 30, "fps": 10}, "objects": [],
      "clouds": [{"count": 100, "center": [0, 0, 0], "radius": 1, "velocity": [10, 0, 0], "drag": 0}],
      "simulation": {"domain": {"min": [-5, -5, -5], "max": [5, 5, 5]}}})";
    Simulator sim(parseScene(text, "leave.json").simulation);
    runFrames(sim, 10); // 1 s at 10 units/s: all beyond x = 5
    CHECK(sim.particles().size() == 0);
    CHECK(sim.removedTotal() == 100);
}

TEST_CASE("simulator: a dynamic object's nose follows its velocity", "[sim]")
{
    const std::string text = R"({"version": 1, "frames": {"start": 1, "end": 3, "fps": 24},
      "objects": [{"name": "dart", "mesh": {"box": {"min": [-1, -0.2, -0.2], "max": [1, 0.2, 0.2]}},
                   "motion": "dynamic", "velocity": [0, 0, -10], "repulsion": false}]})";
    Simulator sim(parseScene(text, "dart.json").simulation);
    sim.advanceFrame();
    const Transform& pose = sim.objectStates()[0].pose;
    const Vec3d nose = pose.rotateToWorld({1, 0, 0});
    CHECK(nose[2] == Approx(-1).margin(1e-9));
    CHECK(pose.translation[2] == Approx(-10.0 / 24.0));
}

TEST_CASE("simulator: a dynamic object rolls at most at its rate, and turning counts in its substeps", "[sim]")
{
    // A sideways field would bank it by about 45 degrees at once; at 90
    // degrees/s it has rolled 22.5 degrees after a quarter of a second. A long dart's tips sweep far as it turns, so it
    // takes more substeps than a short one on the same course.
    const auto dart = [](double halfLength) {
        const std::string text = R"({"version": 1, "frames": {"start": 1, "end": 30, "fps": 24},
          "fields": [{"acceleration": [0, 0, 9.81]}],
          "objects": [{"name": "dart", "mesh": {"box": {"min": [-)" +
                                 std::to_string(halfLength) + R"(, -0.2, -0.2],
                       "max": [)" +
                                 std::to_string(halfLength) + R"(, 0.2, 0.2]}}, "motion": "dynamic",
                       "velocity": [10, 0, 0], "bank": true, "maxRollRate": 90, "repulsion": false}]})";
        return parseScene(text, "dart.json");
    };
    const Scene shortDart = dart(1.0), longDart = dart(10.0);
    Simulator a(shortDart.simulation), b(longDart.simulation);
    double rollAtQuarterSecond = 0.0;
    for (int frame = 2; frame <= 30; ++frame) {
        a.advanceFrame();
        b.advanceFrame();
        INFO("frame " << frame);
        CHECK(a.lastStep().maxRollChange <= 90.0 / 24.0 + 1e-9);
        CHECK(b.lastStep().dynamicSubsteps > a.lastStep().dynamicSubsteps);
        if (frame == 7) rollAtQuarterSecond = a.objectStates()[0].roll;
    }
    // Turning right (+z) banks it right: left wing up, a negative roll.
    CHECK(rollAtQuarterSecond * 180.0 / 3.14159265358979 == Approx(-22.5).margin(1e-6));
}

TEST_CASE("simulator: a fast box through resting particles pushes them aside, none inside it at any frame", "[sim]")
{
    // A box overtaking particles at 50 units/s outruns what its field can
    // accelerate them to: with the field alone, many of them would end up
    // inside it. Counted here against the box itself, exactly, every frame.
    const std::string text = R"({"version": 1, "frames": {"start": 1, "end": 40, "fps": 24}, "seed": 1,
      "objects": [{"name": "box", "mesh": {"box": {"min": [-2, -2, -2], "max": [2, 2, 2]}}, "motion": "dynamic",
                   "transform": {"translate": [-30, 0, 0]}, "mass": 1000, "velocity": [50, 0, 0]}],
      "clouds": [{"count": 20000, "shape": "box", "center": [0, 0, 0], "halfSize": [10, 3, 3], "drag": 0}],
      "simulation": {"domain": {"min": [-100, -50, -50], "max": [100, 50, 50]}}})";
    const Scene scene = parseScene(text, "box.json");
    Simulator sim(scene.simulation);
    const ClearanceProbe probe(sim);
    uint64_t contacts = 0, worstInside = 0;
    for (int frame = 2; frame <= 40; ++frame) {
        sim.advanceFrame();
        contacts += sim.lastStep().contacts;
        const Transform& pose = sim.objectStates()[0].pose;
        uint64_t inside = 0;
        for (const Vec3f& p : sim.particles().position) {
            const Vec3d local = pose.objectFromWorld(Vec3d(p));
            if (std::abs(local[0]) < 2 && std::abs(local[1]) < 2 && std::abs(local[2]) < 2) ++inside;
        }
        worstInside = std::max(worstInside, inside);
        INFO("frame " << frame);
        CHECK(probe.measureParticles().penetrations == 0);
    }
    CHECK(worstInside == 0);
    CHECK(contacts > 0);                                         // the field alone could not do it
    CHECK(sim.objectStates()[0].pose.translation[0] > 30.0);     // the box went through the block
    CHECK(sim.particles().size() + sim.removedTotal() == 20000); // and no particle was lost on the way
}

TEST_CASE("particles: a spatial sort keeps each particle's attributes together and puts neighbours next to each other", "[sim]")
{
    ParticleSet particles;
    std::mt19937 random(3);
    std::uniform_real_distribution<float> u(-50.0f, 50.0f);
    for (uint32_t i = 0; i < 20000; ++i) {
        const Vec3f p(u(random), u(random), u(random));
        particles.position.push_back(p);
        particles.velocity.push_back(p * 2.0f);
        particles.rest.push_back(p * 3.0f);
        particles.id.push_back(i);
        particles.radius.push_back(float(i));
        particles.cloud.push_back(uint16_t(i % 3));
    }
    const auto meanStep = [&] {
        double sum = 0.0;
        for (std::size_t i = 1; i < particles.size(); ++i)
            sum += (Vec3d(particles.position[i]) - Vec3d(particles.position[i - 1])).length();
        return sum / double(particles.size() - 1);
    };
    const double before = meanStep();
    particles.sortSpatially(BBoxd(Vec3d(-50.0), Vec3d(50.0)));
    const double after = meanStep();
    INFO("mean distance between consecutive particles: " << before << " in spawn order, " << after << " sorted");
    CHECK(after < 0.1 * before);
    std::vector<uint8_t> seen(particles.size(), 0);
    for (std::size_t i = 0; i < particles.size(); ++i) {
        const uint32_t id = particles.id[i];
        ++seen[id];
        CHECK(particles.velocity[i] == particles.position[i] * 2.0f);
        CHECK(particles.rest[i] == particles.position[i] * 3.0f);
        CHECK(particles.radius[i] == float(id));
        CHECK(particles.cloud[i] == id % 3);
    }
    CHECK(std::count(seen.begin(), seen.end(), 1) == std::ptrdiff_t(seen.size()));
}

TEST_CASE("simulator: dual rest resets each rest where its weight is zero, half a period apart", "[sim]")
{
    Scene scene = test::singleParticleScene(R"([{"acceleration": [6, 0, 0]}])", 20, 0.0, 24.0);
    scene.simulation.solver.restPeriod = 4;
    Simulator sim(scene.simulation);
    const Vec3f emitted = sim.particles().position[0];
    std::map<int, Vec3f> positions{{1, emitted}};
    for (int frame = 2; frame <= 9; ++frame) {
        sim.advanceFrame();
        positions[frame] = sim.particles().position[0];
    }
    // Frame 9 is two periods in: rest was reset at frames 5 and 9, rest2 at 3 and 7.
    const ParticleSet& particles = sim.particles();
    CHECK(particles.rest[0] == positions[9]);
    CHECK(particles.rest2[0] == positions[7]);
    CHECK(particles.rest2Weight == 1.0f); // rest was just reset: all of the detail from rest2
    sim.advanceFrame();
    CHECK(particles.rest2Weight == 0.5f);
    sim.advanceFrame();
    CHECK(particles.rest2[0] == sim.particles().position[0]); // frame 11: rest2 reset ...
    CHECK(particles.rest2Weight == 0.0f);                     // ... where it has no weight
    CHECK(particles.rest[0] == positions[9]);

    // The saved state carries both rests and the blend.
    Simulator restored(scene.simulation);
    restored.restoreState(sim.serializeState());
    CHECK(restored.particles().rest == particles.rest);
    CHECK(restored.particles().rest2 == particles.rest2);
    CHECK(restored.particles().rest2Weight == particles.rest2Weight);
}

TEST_CASE("simulator: a saved state whose particle count is damaged is refused as truncated", "[sim]")
{
    const Scene scene = test::singleParticleScene(R"([{"acceleration": [6, 0, 0]}])", 20, 0.0, 24.0);
    Simulator sim(scene.simulation);
    sim.advanceFrame();
    std::string bytes = sim.serializeState();
    // The positions' count follows the magic, the frame, the removed count
    // and the object count (the scene has no objects). 2^62 + 1 positions of
    // 12 bytes are 12 bytes modulo 2^64: a reader that multiplies thinks
    // one position remains, and asks for 2^62 + 1 of them.
    REQUIRE(sim.objectStates().empty());
    const std::size_t countAt = sizeof(uint64_t) + sizeof(int32_t) + 2 * sizeof(uint64_t);
    const uint64_t damaged = (uint64_t(1) << 62) + 1;
    REQUIRE(damaged * sizeof(Vec3f) == sizeof(Vec3f));
    std::memcpy(bytes.data() + countAt, &damaged, sizeof damaged);
    Simulator restored(scene.simulation);
    CHECK_THROWS_MATCHES(restored.restoreState(bytes), ValueError,
                         Catch::Matchers::Message("the saved simulation state is truncated"));
}

TEST_CASE("simulator: a preroll moves the clouds before the first frame, holds the objects, and rests the particles where "
          "it ends",
          "[sim]")
{
    // A second of wind at 2 units/s^2 from rest: one unit, as 24 frames after the first would move it.
    const std::string text = R"({"version": 1, "frames": {"start": 1, "end": 30, "fps": 24},
      "objects": [{"name": "crate", "mesh": {"box": {}}, "motion": "dynamic", "repulsion": false,
                   "transform": {"translate": [0, 10, 0]}}],
      "clouds": [{"name": "dust", "count": 5, "center": [0, -10, 0], "radius": 1, "drag": 0}],
      "fields": [{"name": "wind", "acceleration": [2, 0, 0]}],
      "simulation": {"domain": {"min": [-100, -100, -100], "max": [100, 100, 100]}}})";
    Scene scene = parseScene(text, "preroll.json");
    Simulator unrolled(scene.simulation);
    runFrames(unrolled, 24);
    scene.simulation.solver.preroll = 24;
    const Simulator rolled(scene.simulation);
    CHECK(rolled.frame() == 1);
    CHECK(rolled.objectStates()[0].pose.translation == Vec3d(0, 10, 0));
    REQUIRE(rolled.particles().size() == unrolled.particles().size());
    for (std::size_t p = 0; p < rolled.particles().size(); ++p) {
        // Each particle where the same second after the first frame takes it (ids match after the sort).
        const std::size_t q =
            std::size_t(std::find(unrolled.particles().id.begin(), unrolled.particles().id.end(), rolled.particles().id[p]) -
                        unrolled.particles().id.begin());
        REQUIRE(q < unrolled.particles().size());
        CHECK((Vec3d(rolled.particles().position[p]) - Vec3d(unrolled.particles().position[q])).length() < 1e-5);
        CHECK(rolled.particles().rest[p] == rolled.particles().position[p]);
        CHECK(rolled.particles().peak[p] == rolled.particles().position[p].y());
    }
}

TEST_CASE("simulator: air lifted to its condensation level becomes cloud and clears again as it sinks back", "[sim][volume]")
{
    // Thrown up at 10 against -5: it rises 10 units over 2 s and is back where it started at 4 s.
    const std::string text = R"({"version": 1, "frames": {"start": 1, "end": 97, "fps": 24}, "objects": [],
      "clouds": [{"count": 2000, "shape": "sphere", "radius": 2, "velocity": [0, 10, 0], "drag": 0}],
      "fields": [{"acceleration": [0, -5, 0]}],
      "simulation": {"domain": {"min": [-50, -50, -50], "max": [50, 50, 50]}},
      "volume": {"condensation": {"depth": 2, "lift": 6}}})";
    const Scene scene = parseScene(text, "lifted.json");
    Simulator sim(scene.simulation);
    const auto integral = [&] {
        const DensityGrids grids = splatParticles(sim.particles(), scene.volume);
        double sum = 0.0;
        for (auto it = grids.density->cbeginValueOn(); it; ++it) sum += *it;
        return sum * std::pow(grids.density->voxelSize()[0], 3);
    };
    const double full = 2000 * scene.volume.densityPerParticle;
    std::map<int, double> at{{1, integral()}};
    for (int frame = 2; frame <= 97; ++frame) {
        sim.advanceFrame();
        if (frame == 49 || frame == 97) at[frame] = integral();
    }
    CHECK(at[1] < 1e-6 * full);                  // clear air where it starts, 6 below its level
    CHECK(at[49] == Approx(full).epsilon(0.02)); // 10 up: above its level, all condensed
    CHECK(at[97] < 1e-6 * full);                 // back down: evaporated
    CHECK(sim.particles().size() == 2000);
}

TEST_CASE("simulator: a cloud carried down a slope loses density with every frame of descent, by condensation", "[sim][volume]")
{
    // A slab of rock tilted 30 degrees, the cloud resting on its upper end
    // and blown down it: its air sinks from where it was emitted.
    const std::string text = R"({"version": 1, "frames": {"start": 1, "end": 60, "fps": 24}, "seed": 1,
      "objects": [{"name": "slope", "mesh": {"box": {"min": [-40, -2, -10], "max": [40, 0, 10]}, "tessellate": 1},
                   "transform": {"rotateDegrees": [0, 0, -30]}}],
      "clouds": [{"count": 4000, "shape": "ellipsoid", "center": [-25, 18, 0], "radii": [4, 2, 4],
                  "particleRadius": 0.5, "drag": 1}],
      "fields": [{"name": "gravity", "acceleration": [0, -9.81, 0]}, {"name": "downslope", "acceleration": [8.5, -4.9, 0]}],
      "volume": {"condensation": {"depth": 10}}})";
    const Scene scene = parseScene(text, "slope.json");
    Simulator sim(scene.simulation);
    const ClearanceProbe probe(sim);
    const auto integral = [&] {
        const DensityGrids grids = splatParticles(sim.particles(), scene.volume);
        double sum = 0.0;
        for (auto it = grids.density->cbeginValueOn(); it; ++it) sum += *it;
        return sum * std::pow(grids.density->voxelSize()[0], 3);
    };
    const auto meanHeight = [&] {
        double y = 0.0;
        for (const Vec3f& p : sim.particles().position) y += p.y();
        return y / double(sim.particles().size());
    };
    const double full = 4000 * scene.volume.densityPerParticle;
    double previous = integral(), previousHeight = meanHeight();
    CHECK(previous == Approx(full).epsilon(0.02)); // where it was emitted, at its peak: all of it
    int descending = 0;
    for (int frame = 2; frame <= 60; ++frame) {
        sim.advanceFrame();
        const double now = integral(), height = meanHeight();
        INFO("frame " << frame << ": mean height " << height << ", density integral " << now << " of " << full);
        CHECK(probe.measureParticles().penetrations == 0);
        if (height < previousHeight) {
            ++descending;
            CHECK(now <= previous + 1e-4 * full); // to within the float sums' rounding and the cutoff's fringe
        }
        previous = now;
        previousHeight = height;
    }
    CHECK(descending > 50);
    CHECK(previousHeight < 18.0 - 10.0); // depth below where it began: gone
    CHECK(previous < 0.05 * full);
    CHECK(sim.particles().size() == 4000); // the particles are all there: only their density went
}

TEST_CASE("simulator: a cloud pressed onto a wall by wind rests without a step where the wall's leaves change size, "
          "with dual sampling",
          "[sim]")
{
    // A wall facing +z: in 1-unit squares for x < 0 (fine leaves), one square
    // of two triangles for x > 0 (coarse leaves), and a cloud blown onto it.
    TriangleMesh wall;
    for (int x = -24; x < 0; ++x)
        for (int y = -8; y < 8; ++y) test::addSquareFacingUp(wall, x, y, x + 1, y + 1, 0.0);
    test::addSquareFacingUp(wall, 0, -8, 24, 8, 0.0);
    const std::string dir = test::scratchDir("wall");
    saveObj(wall, dir + "/wall.obj");

    // The standoff (mean height) of the particles over the wall's middle, in
    // columns 0.5 units wide across x.
    const auto standoffs = [&](const std::string& sampling) {
        const std::string text = R"({"version": 1, "frames": {"start": 1, "end": 40, "fps": 24}, "seed": 1,
          "objects": [{"name": "wall", "mesh": {"file": ")" +
                                 dir + R"(/wall.obj"},
                       "repulsion": {"margin": 8, "maxLevel": 7, "maxPerLeaf": 4, "growth": "doubling", "strength": 0.5}}],
          "clouds": [{"count": 20000, "shape": "box", "center": [0, 0, 3], "halfSize": [10, 4, 1], "particleRadius": 0.3,
                      "drag": 2}],
          "fields": [{"name": "wind", "acceleration": [0, 0, -6]}],
          "simulation": {"sampling": ")" +
                                 sampling + R"("}})";
        Simulator sim(parseScene(text, dir + "/wall.json").simulation);
        runFrames(sim, 40);
        std::map<int, std::pair<double, int>> columns;
        for (const Vec3f& p : sim.particles().position)
            if (std::abs(p.y()) < 2.0) {
                auto& [sum, count] = columns[int(std::floor(p.x() / 0.5))];
                sum += p.z();
                ++count;
            }
        std::vector<double> heights;
        for (int column = -16; column < 16; ++column) {
            const auto& [sum, count] = columns[column];
            REQUIRE(count > 20);
            heights.push_back(sum / count);
        }
        return heights;
    };
    // How much of the whole change across the columns its largest jump between neighbours makes.
    const auto steepest = [](const std::vector<double>& heights) {
        double jump = 0.0;
        for (std::size_t i = 1; i < heights.size(); ++i) jump = std::max(jump, std::abs(heights[i] - heights[i - 1]));
        const auto [low, high] = std::minmax_element(heights.begin(), heights.end());
        return jump / (*high - *low);
    };
    const std::vector<double> dual = standoffs("dual"), nearest = standoffs("nearest");
    std::ostringstream profile;
    for (std::size_t i = 0; i < dual.size(); ++i) profile << " " << dual[i] << "/" << nearest[i];
    INFO("standoff per 0.5-unit column from x = -8 to 8, dual/nearest:" << profile.str());
    INFO("the largest jump between neighbouring columns: dual " << steepest(dual) << ", nearest " << steepest(nearest)
                                                                << " of the whole change");
    CHECK(steepest(nearest) > 0.5);
    CHECK(steepest(dual) < 0.25);
}
