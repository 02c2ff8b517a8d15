#include "sim_test_scenes.h"
#include "test_meshes.h"

#include <vfield/core/vdb_file.h>
#include <vfield/render/camera.h>
#include <vfield/scene/run_metrics.h>
#include <vfield/scene/simulation_run.h>
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
    // An explicit step overshoots once drag dt > 1: it ran the cloud upwind and
    // cut frames into about 150 substeps. Exactly integrated, the cloud moves
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
    // The substep bound once took the finest leaf of any field in the scene:
    // the shipped airplane, parked far above the terrain, more than doubled
    // every particle's substeps (1.24 -> 2.71 a frame). Now each particle
    // counts the cells of the fields around it.
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
    ObjectSpec airplane;
    airplane.name = "parked airplane";
    airplane.mesh.kind = MeshSource::Kind::File;
    airplane.mesh.path = std::string(VFIELD_SCENES_DIR) + "/meshes/airplane.obj";
    airplane.transform.translation = Vec3d(60, 70, 80);
    airplane.transform.scale = 0.7;
    airplane.repulsion = RepulsionOptions{};
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
    UniformFieldSpec field;
    field.acceleration = Vec3d(0, 0, 4);
    field.box = BBoxd(Vec3d(0.0), Vec3d(10.0));
    field.softEdge = 2.0;
    CHECK(field.accelerationAt({5, 5, 5}) == Vec3d(0, 0, 4));
    CHECK(field.accelerationAt({11, 5, 5}) == Vec3d(0, 0, 2));   // halfway across the edge
    CHECK(field.accelerationAt({12.5, 5, 5}) == Vec3d(0, 0, 0)); // beyond it

    // A particle outside a hard-edged box stays at rest.
    Simulator sim(
        test::singleParticleScene(R"([{"acceleration": [5, 0, 0], "box": {"min": [10, -1, -1], "max": [20, 1, 1]}}])", 25, 0.0)
            .simulation);
    runFrames(sim, 24);
    CHECK(onlyParticle(sim).length() < 1e-8);
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

TEST_CASE("showcase: the cloud squeezes through the pass and pours down beyond it without a penetration", "[sim][showcase]")
{
    const Scene scene = test::showcaseAtTestResolution("cloud_over_terrain.json", 4000, 240);
    const std::string dir = test::scratchDir("cloud-showcase");
    const SimulateSummary summary = simulateScene(scene, dir, {240, 240, {}, {}});
    CHECK(summary.worstParticles.penetrations == 0);
    CHECK(summary.worstParticles.minimum > 1.0);
    // Across the wind (z) the cloud is squeezed where the pass cuts the ridge
    // (x about 15); beyond it, its lower edge sinks into the valley, and it is
    // still there, in view, at the last frame.
    const auto frame = [&](int f) -> const FrameRecord& { return summary.frames.at(std::size_t(f - 1)); };
    const auto width = [&](int f) { return frame(f).bounds.max()[2] - frame(f).bounds.min()[2]; };
    const double start = width(1), inPass = width(161);
    const double bottomInPass = frame(161).bounds.min()[1], bottomBeyond = frame(240).bounds.min()[1];
    INFO("z extent " << start << " -> " << inPass << "; bottom " << bottomInPass << " -> " << bottomBeyond << "; x "
                     << frame(161).centroid[0] << " -> " << frame(240).centroid[0] << "; alive " << frame(240).alive);
    CHECK(frame(161).centroid[0] == Approx(10).margin(10));
    CHECK(inPass < 0.5 * start);
    CHECK(frame(240).centroid[0] > 60.0);
    CHECK(bottomBeyond < bottomInPass - 8.0);
    CHECK(frame(240).alive > 0.99 * 4000);
}

TEST_CASE("showcase: the cloud bank climbs the ridge along the ground, crosses it and sinks beyond, without a penetration",
          "[sim][showcase]")
{
    const Scene scene = test::showcaseAtTestResolution("cloud_bank.json", 4000, 240);
    const TerrainOptions& terrain = scene.simulation.objects.at(0).mesh.terrain;
    const double crestX = terrain.carves.at(0).path.at(0)[0]; // the ridge runs along z there
    Simulator sim(scene.simulation);
    const ClearanceProbe probe(sim);
    // The particles upwind of the ridge's top (x below crestX - 20) and beyond
    // it (x above crestX + 20): how many, their mean height above the ground
    // below them and their mean altitude.
    struct Band {
        std::size_t count = 0;
        double aboveGround = 0.0, altitude = 0.0;
    };
    const auto bands = [&] {
        std::array<Band, 2> b;
        for (const Vec3f& p : sim.particles().position) {
            if (std::abs(p[0] - crestX) <= 20.0) continue;
            Band& band = b[p[0] < crestX ? 0 : 1];
            ++band.count;
            band.aboveGround += p[1] - terrainHeight(terrain, p[0], p[2]);
            band.altitude += p[1];
        }
        for (Band& band : b)
            if (band.count > 0) {
                band.aboveGround /= double(band.count);
                band.altitude /= double(band.count);
            }
        return b;
    };
    // How many particles the scene's camera has in its frame (1280x720).
    const Camera camera = Camera::fromSettings(scene.render.camera, 1280, 720);
    const auto inFrame = [&] {
        std::size_t count = 0;
        for (const Vec3f& p : sim.particles().position) {
            const Vec3d d = Vec3d(p) - camera.position();
            const double depth = d.dot(camera.forward());
            count += depth > 0.0 && std::abs(d.dot(camera.right())) <= depth * camera.tanHalfFov() * camera.aspect() &&
                     std::abs(d.dot(camera.up())) <= depth * camera.tanHalfFov();
        }
        return count;
    };
    std::size_t fewestInFrame = inFrame();
    std::map<int, std::array<Band, 2>> at{{1, bands()}};
    double minimumClearance = std::numeric_limits<double>::max();
    uint64_t penetrations = 0;
    double highest = 0.0; // the highest altitude any particle reached, at any frame
    for (int frame = 2; frame <= 240; ++frame) {
        sim.advanceFrame();
        const ClearanceStats stats = probe.measureParticles();
        minimumClearance = std::min(minimumClearance, stats.minimum);
        penetrations += stats.penetrations;
        for (const Vec3f& p : sim.particles().position) highest = std::max(highest, double(p[1]));
        fewestInFrame = std::min(fewestInFrame, inFrame());
        if (frame % 40 == 0) at[frame] = bands();
    }
    double crestHeight = 0.0; // the ridge's highest point along its line
    for (double z = -200.0; z <= 200.0; z += 1.0) crestHeight = std::max(crestHeight, terrainHeight(terrain, crestX, z));
    const Band &start = at[1][0], &climbing = at[120][0], &beyond = at[200][1], &end = at[240][1];
    INFO("upwind at frame 1: " << start.count << " particles at altitude " << start.altitude
                               << "; at frame 120: " << climbing.count << ", " << climbing.aboveGround
                               << " above the ground at altitude " << climbing.altitude
                               << "; beyond at frame 200: " << beyond.count << " at altitude " << beyond.altitude
                               << "; at frame 240: " << end.count << " at altitude " << end.altitude << " (crest " << crestHeight
                               << "), " << end.aboveGround << " above the ground; highest " << highest << "; clearance "
                               << minimumClearance << "; in the camera's frame at least " << fewestInFrame);
    CHECK(penetrations == 0);
    CHECK(minimumClearance > 0.0);
    CHECK(start.count == sim.particles().size()); // the bank starts upwind of the ridge
    // Climbing the windward slope, it rises with the ground and stays close to it ...
    CHECK(climbing.altitude > start.altitude + 8.0);
    CHECK(climbing.aboveGround < 15.0);
    // ... crosses the top, and sinks down the far side, below the crest.
    CHECK(end.count > 0.99 * double(sim.particles().size()));
    CHECK(end.altitude < beyond.altitude - 3.0);
    CHECK(end.altitude < crestHeight);
    // Nothing is flung skyward (a field growing linearly with a surface boost of 20 threw plumes beyond this).
    CHECK(highest < crestHeight + 40.0);
    // The whole bank is in view from the first frame to the last.
    CHECK(fewestInFrame == sim.particles().size());
}

TEST_CASE("showcase: the octree and distance fields keep the cloud off the terrain, a potential flow hugs it",
          "[sim][showcase][methods]")
{
    std::map<RepulsionMethod, SimulateSummary> runs;
    for (const RepulsionMethod method : {RepulsionMethod::Octree, RepulsionMethod::Distance, RepulsionMethod::PotentialFlow}) {
        Scene scene = test::showcaseAtTestResolution("cloud_over_terrain.json", 2000, 240);
        scene.simulation.objects.at(0).repulsion->method = method;
        const std::string dir = test::scratchDir(std::string("methods-") + enumName(method));
        const SimulateSummary summary = simulateScene(scene, dir, {200, 240, {}, {}}); // paths from the frames written
        const RunMetrics metrics = measureRun(dir);
        INFO(enumName(method) << ": clearance " << summary.worstParticles.minimum << ", 1st percentile "
                              << summary.worstParticles.percentile1 << ", penetrations " << summary.worstParticles.penetrations
                              << ", curvature " << metrics.meanCurvature);
        REQUIRE(metrics.fields.size() == 1);
        CHECK(metrics.fields[0].method == enumName(method));
        CHECK(metrics.fields[0].memoryBytes > 0);
        CHECK(metrics.minClearance == summary.worstParticles.minimum);
        CHECK(metrics.penetrations == summary.worstParticles.penetrations);
        CHECK(metrics.meanCurvature > 0.0);
        CHECK(metrics.substepsPerParticleFrame >= 1.0);
        if (method != RepulsionMethod::PotentialFlow) {
            CHECK(summary.worstParticles.penetrations == 0);
            CHECK(summary.worstParticles.minimum > 0.0);
        }
        runs[method] = summary;
    }
    // The flow carries the cloud along the ground's contour, closer than the
    // octree's field lets it come; nothing pushes back where its steps cut a
    // corner, so it does not promise what the fields do (the README's table).
    CHECK(runs[RepulsionMethod::PotentialFlow].worstParticles.percentile1 <
          runs[RepulsionMethod::Octree].worstParticles.percentile1);
}

TEST_CASE("showcase: the airplane flies the canyon without touching it", "[sim][showcase]")
{
    const Scene scene = test::showcaseAtTestResolution("canyon_flythrough.json", 0, 330);
    const std::string dir = test::scratchDir("canyon-showcase");
    const SimulateSummary summary = simulateScene(scene, dir, {330, 330, {}, {}});
    REQUIRE(summary.closestPairs.size() == 1); // the airplane and the mountains, mesh to mesh
    CHECK(summary.overlappingPairFrames == 0);
    CHECK(summary.closestPairs[0].minimum > 0.3);
    // Its roll turns at most at its rate (120 degrees/s in the scene): once it
    // flipped by 108 degrees within a frame.
    for (const FrameRecord& r : summary.frames) {
        INFO("frame " << r.frame);
        CHECK(r.maxRollChange <= 120.0 / 24.0 + 1e-9);
    }
    // It flies the whole canyon, below its rims, and never stalls.
    std::ifstream in(dir + "/tracks.json");
    const nlohmann::json track = nlohmann::json::parse(in).at("objects").at("airplane");
    double slowest = 1e9, highest = -1e9;
    for (const nlohmann::json& entry : track) {
        const auto v = entry.at("velocity").get<std::vector<double>>();
        slowest = std::min(slowest, std::hypot(v[0], v[2]));
        highest = std::max(highest, entry.at("position").at(1).get<double>());
    }
    CHECK(track.back().at("position").at(0).get<double>() > 140.0); // past the terrain's far edge
    CHECK(slowest > 3.0);
    CHECK(highest < 10.0); // the rims stand at about 20 and higher
}

namespace {

/// The crossing flights up to just past their meetings: each pair's closest
/// approach over every substep, mesh to mesh.
std::map<std::string, PairClearance> closestApproaches(const std::vector<SceneOverride>& overrides)
{
    const std::string path = std::string(VFIELD_SCENES_DIR) + "/crossing_flights.json";
    std::vector<SceneOverride> all = overrides;
    all.push_back({"/frames/end", "140"});
    Simulator sim(loadScene(path, all).simulation);
    const ClearanceProbe probe(sim);
    std::map<std::string, PairClearance> closest;
    const auto measure = [&] {
        for (const PairClearance& pair : probe.measureObjects()) {
            const auto [it, added] = closest.emplace(pair.first + "-" + pair.second, pair);
            if (!added && pair.minimum < it->second.minimum) it->second = pair;
        }
    };
    while (sim.frame() < sim.setup().lastFrame) sim.advanceFrame(measure);
    return closest;
}

} // namespace

TEST_CASE("showcase: four aircraft on collision courses never touch, and touch without their fields", "[sim][showcase]")
{
    const std::map<std::string, PairClearance> repelled = closestApproaches({});
    REQUIRE(repelled.size() == 10); // four aircraft: six pairs, and each against the mountains
    for (const auto& [pair, clearance] : repelled) {
        INFO(pair << " " << clearance.minimum);
        CHECK(clearance.minimum > 0.5);
    }
    // The same courses with the aircraft's fields at zero strength.
    std::vector<SceneOverride> unrepelled;
    for (int object = 1; object <= 4; ++object)
        unrepelled.push_back({"/objects/" + std::to_string(object) + "/repulsion/strength", "0"});
    const std::map<std::string, PairClearance> collided = closestApproaches(unrepelled);
    CHECK(collided.at("red-blue").minimum < 0.0);     // head-on
    CHECK(collided.at("yellow-white").minimum < 0.0); // crossing
}

TEST_CASE("showcase: an airplane through a cloud bank parts it, no particle inside it at any substep", "[sim][showcase]")
{
    // 20,000 of the bank's particles; by frame 90 the airplane is past the
    // bank's middle.
    Scene scene = test::showcaseAtTestResolution("plane_through_cloud.json", 20000, 90);
    Simulator sim(scene.simulation);
    const ClearanceProbe probe(sim);
    // The flight line's tube (the airplane's height and half its span)
    // between where the cloud begins and x = -5, which it has left by then.
    const auto inTube = [&] {
        std::size_t n = 0;
        for (const Vec3f& p : sim.particles().position)
            if (p[0] > -40.0f && p[0] < -5.0f && std::abs(p[1]) < 1.0f && std::abs(p[2]) < 3.0f) ++n;
        return n;
    };
    const std::size_t before = inTube();
    REQUIRE(before > 100);
    uint64_t endedInside = 0, contacts = 0;
    while (sim.frame() < sim.setup().lastFrame) {
        sim.advanceFrame();
        endedInside += sim.lastStep().endedInside;
        contacts += sim.lastStep().contacts;
        const ClearanceStats clearance = probe.measureParticles();
        INFO("frame " << sim.frame());
        CHECK(clearance.penetrations == 0);
    }
    const Transform& airplane = sim.objectStates()[1].pose;
    REQUIRE(airplane.translation[0] > 10.0); // its tail past the tube
    CHECK(endedInside == 0);
    INFO("contacts " << contacts << ", particles in the tube before " << before << ", after " << inTube());
    CHECK(inTube() < before / 4); // the wake
}

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
    scene.simulation.options.restPeriod = 6; // both rests reset before and after the kill
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
    billowed.simulation.options.restPeriod = 2;
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

TEST_CASE("simulator: a fast box through resting particles pushes them aside, none inside it at any frame", "[sim]")
{
    // A box overtaking particles at 50 units/s outruns what its field can
    // accelerate them to: with the field alone about 1,800 of them ended
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
    scene.simulation.options.restPeriod = 4;
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
