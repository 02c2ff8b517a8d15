#pragma once
// The showcase's own samples per pixel, shared by the benchmarks and their report.

namespace vfield::bench {

/// scenes/cloud_over_terrain.json's samplesPerPixel: where a surface's
/// shading noise, drawn once a pixel, is shared by the pixel's samples.
/// ShowcaseFrame checks that the scene still says so.
constexpr int kShowcaseSamplesPerPixel = 3;

} // namespace vfield::bench
