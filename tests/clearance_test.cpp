// The clearance probe: signed distances to the scene's static meshes.

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
    const TerrainOptions& terrain = scene.simulation.objects[0].mesh.terrain;
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
