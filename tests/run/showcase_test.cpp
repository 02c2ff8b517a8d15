// The showcase scenes at test resolution: each does what docs/showcase.md says it
// does, measured (clearances against exact level sets, extents, altitudes).

#include "sim_test_scenes.h"
#include "test_meshes.h"

#include <vfield/core/vdb_file.h>
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

TEST_CASE("showcase: the cloud squeezes through the pass and pours down beyond it without a penetration", "[sim][showcase]")
{
    const Scene scene = test::showcaseAtTestResolution("cloud_over_terrain.json", 4000, 240);
    const std::string dir = test::scratchDir("cloud-showcase");
    const SimulateSummary summary = simulateScene(scene, dir, SimulateOptions::writing(240, 240));
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
    const TerrainSettings& terrain = scene.simulation.objects.at(0).mesh.terrain;
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
    // The particles that still carry density (those sunk the condensation's
    // depth below their peak have evaporated) outside the scene's camera's
    // frame (its resolution's aspect).
    const Camera camera = Camera::fromSettings(scene.render.camera, scene.render.image.width, scene.render.image.height);
    const CondensationSettings& condensation = scene.volume.condensation;
    const auto visibleOutOfFrame = [&] {
        const ParticleSet& particles = sim.particles();
        std::size_t count = 0;
        for (std::size_t i = 0; i < particles.size(); ++i) {
            const Vec3d d = Vec3d(particles.position[i]) - camera.position();
            const double depth = d.dot(camera.forward());
            const bool inFrame = depth > 0.0 &&
                                 std::abs(d.dot(camera.right())) <= depth * camera.tanHalfFov() * camera.aspect() &&
                                 std::abs(d.dot(camera.up())) <= depth * camera.tanHalfFov();
            const float y = particles.position[i].y(), peak = particles.peak.size() == particles.size() ? particles.peak[i] : y;
            const float origin = particles.origin.size() == particles.size() ? particles.origin[i] : y;
            count += !inFrame && condensation.share(y, peak, origin) > 0.0f;
        }
        return count;
    };
    std::size_t mostVisibleOutOfFrame = visibleOutOfFrame();
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
        mostVisibleOutOfFrame = std::max(mostVisibleOutOfFrame, visibleOutOfFrame());
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
                               << minimumClearance << "; visible beyond the camera's frame at most " << mostVisibleOutOfFrame);
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
    // Nothing is flung skyward (a field growing linearly with a surface boost of 20 would throw plumes beyond this).
    CHECK(highest < crestHeight + 40.0);
    // The whole visible bank is in view from the first frame to the last
    // (by the last frame some particles have sunk below the frame's lower
    // edge, evaporated).
    CHECK(mostVisibleOutOfFrame == 0);
}

TEST_CASE("showcase: the octree and distance fields keep the cloud off the terrain, a potential flow hugs it",
          "[sim][showcase][methods]")
{
    std::map<RepulsionMethod, SimulateSummary> runs;
    for (const RepulsionMethod method : {RepulsionMethod::Octree, RepulsionMethod::Distance, RepulsionMethod::PotentialFlow}) {
        Scene scene = test::showcaseAtTestResolution("cloud_over_terrain.json", 2000, 240);
        scene.simulation.objects.at(0).repulsion->method = method;
        const std::string dir = test::scratchDir(std::string("methods-") + enumName(method));
        const SimulateSummary summary =
            simulateScene(scene, dir, SimulateOptions::writing(200, 240)); // paths from the frames written
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
    // corner, so it does not promise what the fields do (docs/octree-field.md,
    // "Choosing a repulsion method").
    CHECK(runs[RepulsionMethod::PotentialFlow].worstParticles.percentile1 <
          runs[RepulsionMethod::Octree].worstParticles.percentile1);
}

TEST_CASE("showcase: the airplane flies the canyon without touching it", "[sim][showcase]")
{
    const Scene scene = test::showcaseAtTestResolution("canyon_flythrough.json", 0, 330);
    const std::string dir = test::scratchDir("canyon-showcase");
    const SimulateSummary summary = simulateScene(scene, dir, SimulateOptions::writing(330, 330));
    REQUIRE(summary.closestPairs.size() == 1); // the airplane and the mountains, mesh to mesh
    CHECK(summary.overlappingPairFrames == 0);
    CHECK(summary.closestPairs[0].minimum > 0.3);
    // Its roll turns at most at its rate (120 degrees/s in the scene):
    // unlimited, it could flip by over 100 degrees within a frame.
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
    // The flight line's tube (about the airplane's height, 3 units, and half
    // its span) between where the cloud begins and x = -5, which it has left
    // by then.
    const double flightHeight = scene.simulation.objects.at(1).transform.translation[1];
    const auto inTube = [&] {
        std::size_t n = 0;
        for (const Vec3f& p : sim.particles().position)
            if (p[0] > -40.0f && p[0] < -5.0f && std::abs(p[1] - flightHeight) < 1.5 && std::abs(p[2]) < 3.0f) ++n;
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

TEST_CASE("showcase: the cap cloud stands over the crest while its air flows through it, without a penetration",
          "[sim][showcase]")
{
    // An eighth of the air, each particle eight times as dense, the look's voxels doubled.
    Scene scene = test::showcaseAtTestResolution("cap_cloud.json", 400000, 48);
    CloudEmissionSettings& emission = *scene.simulation.clouds[0].emission;
    emission.rate /= 8.0;
    scene.volume.densityPerParticle *= 8.0;
    scene.volume.voxelSize *= 2.0;
    const std::string dir = test::scratchDir("showcase-cap-cloud");
    simulateScene(scene, dir);
    const RunMetrics metrics = measureRun(dir);
    INFO("centroid at " << metrics.meanCentroid << " wandered " << metrics.centroidWander << " over a cloud "
                        << metrics.cloudLength << " long; particles at a median " << metrics.medianSpeed << " units/s");
    CHECK(metrics.penetrations == 0);
    // A cloud of a size, standing: its centroid within a tenth of its length,
    // while the air crosses it at the wind's terminal speed (acceleration / drag).
    CHECK(metrics.cloudLength > 50.0);
    CHECK(metrics.centroidWander < 0.1 * metrics.cloudLength);
    // Over the crest (x = 0, 75 above the plain), not along the whole stream
    // from the emitter 150 upwind to the lee: the air condenses as it climbs.
    CHECK(std::abs(metrics.meanCentroid[0]) < 30.0);
    CHECK(metrics.meanCentroid[1] > 60.0);
    CHECK(metrics.cloudLength < 200.0);
    const double windSpeed = scene.simulation.fields[0].acceleration[0] / scene.simulation.clouds[0].drag;
    CHECK(metrics.medianSpeed == Approx(windSpeed).epsilon(0.2));
    // Over the second half (24 frames, a second) the air moves five times as far as the cloud does.
    CHECK(metrics.medianSpeed * 1.0 > 5.0 * metrics.centroidWander);
}
