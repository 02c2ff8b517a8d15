#include "sim_test_scenes.h"
#include "test_meshes.h"

#include <vfield/run/run_metrics.h>
#include <vfield/run/simulation_run.h>

#include <catch2/catch.hpp>

#include <cmath>

using namespace vfield;

namespace {

/// A box coasting along x, slowed by its drag, and a cloud falling through
/// still air beside it; no repulsion anywhere.
Scene coastingScene(double boxDrag)
{
    return parseScene(R"({"version": 1, "frames": {"start": 1, "end": 96, "fps": 24},
      "objects": [{"name": "box", "mesh": {"box": {}}, "motion": "dynamic", "repulsion": false,
                   "velocity": [10, 0, 0], "drag": )" +
                          std::to_string(boxDrag) + R"(}],
      "clouds": [{"name": "rain", "count": 500, "center": [0, 100, 50], "radius": 3, "drag": 0.5}],
      "fields": [{"name": "gravity", "acceleration": [0, -9.81, 0], "affects": ["rain"]}],
      "simulation": {"domain": {"min": [-1000, -1000, -1000], "max": [1000, 1000, 1000]}}})",
                      "coasting.json");
}

} // namespace

TEST_CASE("run metrics: a steady course has no jerk and no stall, a straight fall no curvature", "[metrics]")
{
    const std::string dir = test::scratchDir("metrics-steady");
    simulateScene(coastingScene(0.0), dir);
    const RunMetrics m = measureRun(dir);
    CHECK(m.frames == 96);
    CHECK(m.particles == 500);
    CHECK(m.fields.empty());
    CHECK(m.trapped == 0);
    CHECK(m.meanCurvature < 1e-6);
    REQUIRE(m.objects.size() == 1);
    CHECK(m.objects[0].name == "box");
    CHECK(m.objects[0].cruiseSpeed == Approx(10.0));
    CHECK(m.objects[0].meanJerk == Approx(0.0).margin(1e-6));
    CHECK(m.objects[0].stallSeconds == 0.0);
    CHECK(m.simulateSeconds > 0.0);
}

TEST_CASE("run metrics: an aircraft that slows to a crawl stalls, for as long as it crawls", "[metrics]")
{
    // Speed 10 e^(-3 t) over 4 s: the median speed is reached at t = 2, and
    // 10% of it ln(10) / 3 = 0.77 s later, so it crawls for the last 1.23 s.
    const std::string dir = test::scratchDir("metrics-stall");
    simulateScene(coastingScene(3.0), dir);
    const RunMetrics m = measureRun(dir);
    REQUIRE(m.objects.size() == 1);
    CHECK(m.objects[0].stallSeconds == Approx(1.23).margin(0.05));
    // Its deceleration shrinks as it slows: jerk 3^2 x 10 e^(-3 t), largest
    // where the first second difference of the frames' velocities is centred.
    CHECK(m.objects[0].peakJerk == Approx(90.0 * std::exp(-3.0 / 24.0)).epsilon(0.01));
}

TEST_CASE("run metrics: a folder without a simulation is refused, naming the file", "[metrics]")
{
    const std::string dir = test::scratchDir("metrics-empty");
    CHECK_THROWS_WITH(measureRun(dir), Catch::Contains("stats.json") && Catch::Contains("simulate the scene first"));
}
