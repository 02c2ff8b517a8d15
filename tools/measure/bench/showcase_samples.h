#pragma once
// The showcases' own settings that the benchmarks' rows are named by, shared
// by the benchmarks and their report.

#include <cstdint>

namespace vfield::bench {

/// scenes/cloud_over_terrain.json's samplesPerPixel: where a surface's
/// shading noise, drawn once a pixel, is shared by the pixel's samples.
/// ShowcaseFrame checks that the scene still says so.
constexpr int kShowcaseSamplesPerPixel = 3;

/// scenes/cloud_bank.json's particle count (the main job's); mainJobAtFrame120
/// checks that the scene still says so.
constexpr int64_t kMainJobParticles = 250'000;

} // namespace vfield::bench
