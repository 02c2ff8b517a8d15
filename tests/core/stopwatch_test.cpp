// Stopwatch: the laps a run times and the pace at which progress is told.

#include <vfield/core/stopwatch.h>

#include <catch2/catch.hpp>

#include <chrono>
#include <thread>

using namespace vfield;

TEST_CASE("stopwatch: lapAfter says yes once its period has passed, then waits a period again", "[core]")
{
    Stopwatch watch;
    CHECK_FALSE(watch.lapAfter(3600.0)); // an hour has not passed since it was made
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    CHECK(watch.lapAfter(0.01));
    CHECK_FALSE(watch.lapAfter(3600.0)); // restarted by the lap above
    CHECK(watch.lapAfter(0.0));          // a period of nothing has always passed
}
