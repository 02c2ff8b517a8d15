// The clearance probe: signed distances to the scene's meshes, point to mesh and mesh to mesh.

#include "sim_test_scenes.h"

#include <vfield/mesh/procedural.h>
#include <vfield/sim/clearance.h>
#include <vfield/sim/simulator.h>

#include <catch2/catch.hpp>

using namespace vfield;

TEST_CASE("clearance: points just below the terrain count as inside", "[sim]")
{
    const Scene scene = test::showcaseAtTestResolution("cloud_over_terrain.json", 10, 2);
    const Simulator sim(scene.simulation);
    const ClearanceProbe probe(sim);
    REQUIRE(probe.warnings().empty()); // the terrain is closed
    const TerrainSettings& terrain = scene.simulation.objects[0].mesh.terrain;
    for (const Vec2d& xz : {Vec2d(0, 0), Vec2d(-40, 30), Vec2d(45, -20), Vec2d(-90, 80)}) {
        const double h = terrainHeight(terrain, xz[0], xz[1]);
        INFO("at x " << xz[0] << " z " << xz[1] << " height " << h);
        CHECK(probe.distance({xz[0], h - 0.3, xz[1]}) < 0.0);
        CHECK(probe.distance({xz[0], h + 0.6, xz[1]}) > 0.0);
        // Three units above the ground lie 3 n_y from its tangent plane.
        const double e = 0.01;
        const Vec3d normal =
            Vec3d(-(terrainHeight(terrain, xz[0] + e, xz[1]) - terrainHeight(terrain, xz[0] - e, xz[1])) / (2 * e), 1.0,
                  -(terrainHeight(terrain, xz[0], xz[1] + e) - terrainHeight(terrain, xz[0], xz[1] - e)) / (2 * e))
                .unitSafe();
        CHECK(probe.distance({xz[0], h + 3.0, xz[1]}) == Approx(3.0 * normal[1]).margin(0.5));
    }
}

namespace {

/// A static blade and a dynamic object at rest (no fields, no motion): what
/// the probe measures between their meshes.
std::vector<PairClearance> measureBladeAndPlate(const std::string& bladeBox, const std::string& plateBox)
{
    const std::string text = R"({"version": 1, "frames": {"start": 1, "end": 2, "fps": 24},
      "objects": [{"name": "blade", "mesh": {"box": )" +
                             bladeBox + R"(}, "repulsion": false},
                  {"name": "plate", "mesh": {"box": )" +
                             plateBox + R"(}, "motion": "dynamic", "repulsion": false}]})";
    const Simulator sim(parseScene(text, "blade.json").simulation);
    return ClearanceProbe(sim).measureObjects();
}

} // namespace

TEST_CASE("clearance: a ridge through the middle of a plate counts, though no vertex touches it", "[sim]")
{
    // The plate's eight vertices lie 4 units from the blade; the blade cuts
    // through its middle.
    const std::vector<PairClearance> pairs =
        measureBladeAndPlate(R"({"min": [-0.1, -3, -5], "max": [0.1, 3, 5]})", R"({"min": [-4, -0.2, -4], "max": [4, 0.2, 4]})");
    REQUIRE(pairs.size() == 1);
    CHECK(pairs[0].first == "plate");
    CHECK(pairs[0].second == "blade");
    CHECK(pairs[0].minimum < 0.0);
}

TEST_CASE("clearance: two boxes a known distance apart measure that distance, mesh to mesh", "[sim]")
{
    // Faces 0.12 apart across x (within the level sets' bands, 0.2 and 0.6
    // here; farther reads as the band); the boxes overlap in y and z.
    const std::vector<PairClearance> pairs =
        measureBladeAndPlate(R"({"min": [-1, -1, -1], "max": [1, 1, 1]})", R"({"min": [1.12, -0.5, -3], "max": [3.12, 0.5, 3]})");
    REQUIRE(pairs.size() == 1);
    CHECK(pairs[0].minimum == Approx(0.12).margin(0.005));
    // End-on: a long box whose small end face lies 0.07 from the cube.
    const std::vector<PairClearance> turned = measureBladeAndPlate(R"({"min": [-1, -1, -1], "max": [1, 1, 1]})",
                                                                   R"({"min": [1.07, -0.5, -0.5], "max": [7.07, 0.5, 0.5]})");
    CHECK(turned[0].minimum == Approx(0.07).margin(0.005));
}

TEST_CASE("clearance: objects that pass through each other between two frames are caught at a substep", "[sim]")
{
    // Two boxes 40 units apart close at 120 units/s with no field between
    // them: after one frame (1 s) they are apart again, on each other's side.
    const std::string text = R"({"version": 1, "frames": {"start": 1, "end": 2, "fps": 1},
      "objects": [{"name": "east", "mesh": {"box": {}}, "motion": "dynamic", "repulsion": false,
                   "transform": {"translate": [-20, 0, 0]}, "velocity": [60, 0, 0]},
                  {"name": "west", "mesh": {"box": {}}, "motion": "dynamic", "repulsion": false,
                   "transform": {"translate": [20, 0, 0]}, "velocity": [-60, 0, 0]}]})";
    Simulator sim(parseScene(text, "pass.json").simulation);
    const ClearanceProbe probe(sim);
    double closest = std::numeric_limits<double>::infinity();
    sim.advanceFrame([&] { closest = std::min(closest, probe.measureObjects().at(0).minimum); });
    REQUIRE(probe.measureObjects().size() == 1);
    CHECK(probe.measureObjects()[0].minimum > 0.0);          // at the frame they are apart
    CHECK(sim.objectStates()[0].pose.translation[0] > 20.0); // past each other
    CHECK(closest < -0.5);                                   // overlapping at substeps between (a box reads -1 at its centre)
    CHECK(probe.measureObjects()[0].exact == false);         // 40 apart: beyond what the level sets measure
}
