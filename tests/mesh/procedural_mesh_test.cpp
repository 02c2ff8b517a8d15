#include <vfield/core/error.h>
#include <vfield/mesh/procedural.h>

#include "test_meshes.h"

#include <catch2/catch.hpp>

#include <OpenImageIO/imagebuf.h>

#include <algorithm>

using namespace vfield;

TEST_CASE("procedural terrain: a closed solid wound outward", "[mesh]")
{
    TerrainSettings options;
    options.cellsX = 40;
    options.cellsZ = 30;
    const TriangleMesh terrain = makeTerrain(options);
    CHECK(terrain.triangleCount() == 2 * 40 * 30 + 3 * 2 * (40 + 30));
    CHECK(analyzeTopology(terrain).isClosed());
    CHECK(signedVolume(terrain) > 0.0);
    const BBoxd box = terrain.bounds();
    CHECK(box.min()[0] == Approx(-100));
    CHECK(box.max()[2] == Approx(100));
}

TEST_CASE("procedural terrain: the surface follows terrainHeight and the seed decides it", "[mesh]")
{
    TerrainSettings options;
    options.cellsX = options.cellsZ = 8;
    const TriangleMesh terrain = makeTerrain(options);
    // Grid point (i, k) is stored at i * (cellsZ + 1) + k.
    const Vec3f p = terrain.points[3 * 9 + 5];
    CHECK(p[0] == Approx(-100 + 200 * 3 / 8.0));
    CHECK(p[2] == Approx(-100 + 200 * 5 / 8.0));
    CHECK(p[1] == Approx(terrainHeight(options, p[0], p[2])).margin(1e-4));

    TerrainSettings other = options;
    other.seed = 2;
    CHECK(terrainHeight(options, 10, 20) == terrainHeight(options, 10, 20));
    CHECK(terrainHeight(options, 10, 20) != terrainHeight(other, 10, 20));
}

TEST_CASE("procedural terrain: a carve lowers its path by its depth and leaves the far ground alone", "[mesh]")
{
    TerrainSettings flat;
    flat.amplitude = 0.0;
    TerrainSettings carved = flat;
    carved.carves.push_back({{{-100, 0}, {0, 40}, {100, 0}}, 20.0, 12.0, 3.0, 0.0, std::nullopt});
    CHECK(terrainHeight(carved, -100, 0) == Approx(-12.0));
    CHECK(terrainHeight(carved, 0, 40) == Approx(-12.0));
    CHECK(terrainHeight(carved, 0, -60) == Approx(0.0));
    // A negative depth raises a ridge.
    carved.carves[0].depth = -8.0;
    CHECK(terrainHeight(carved, 100, 0) == Approx(8.0));
}

TEST_CASE("procedural terrain: a carve with a floor height levels rugged ground to it and keeps the relief beyond", "[mesh]")
{
    TerrainSettings mountains;
    mountains.style = TerrainStyle::Ridged;
    mountains.amplitude = 40.0;
    TerrainSettings carved = mountains;
    CarveSettings canyon{{{-100, 0}, {0, 40}, {100, 0}}, 20.0, 0.0, 3.0, 0.0, -15.0};
    carved.carves.push_back(canyon);
    // On the path the floor is level whatever the mountains' height there.
    CHECK(terrainHeight(mountains, -100, 0) != Approx(terrainHeight(mountains, 0, 40)));
    for (const Vec2d& onPath : canyon.path) CHECK(terrainHeight(carved, onPath[0], onPath[1]) == Approx(-15.0));
    // Beyond halfWidth the ridged relief is untouched.
    for (double z : {-60.0, -45.0, 90.0}) CHECK(terrainHeight(carved, 7.0, z) == Approx(terrainHeight(mountains, 7.0, z)));
}

TEST_CASE("procedural terrain: rough walls wander in and out along the carve, the floor stays", "[mesh]")
{
    TerrainSettings flat;
    flat.amplitude = 0.0;
    flat.carves.push_back({{{-200, 0}, {200, 0}}, 20.0, 10.0, 4.0, 5.0, std::nullopt});
    // Where the wall meets the plain: the first z from the path that is not cut.
    const auto rim = [&](double x) {
        double z = 0.0;
        while (terrainHeight(flat, x, z) < -1e-9) z += 0.05;
        return z;
    };
    double nearest = 1e9, farthest = 0.0;
    for (double x = -150.0; x <= 150.0; x += 5.0) {
        nearest = std::min(nearest, rim(x));
        farthest = std::max(farthest, rim(x));
        CHECK(terrainHeight(flat, x, 0.0) == Approx(-10.0).margin(0.05));
    }
    INFO("rims between " << nearest << " and " << farthest);
    CHECK(farthest - nearest > 3.0); // straight walls would all end at 20
    CHECK(nearest > 20.0 - 2 * 5.0);
    CHECK(farthest < 20.0 + 2 * 5.0);
    flat.carves[0].wallRoughness = 0.0;
    CHECK(rim(33.0) == Approx(20.0).margin(0.06));
}

TEST_CASE("procedural terrain: options out of range are refused", "[mesh]")
{
    TerrainSettings options;
    options.cellsX = 0;
    CHECK_THROWS_AS(makeTerrain(options), ValueError);
    options = {};
    options.cellsX = options.cellsZ = 100000;
    CHECK_THROWS_WITH(makeTerrain(options), Catch::Contains("at most"));
    options = {};
    options.carves.push_back({{{0, 0}}, 10, 10, 1, 0, std::nullopt});
    CHECK_THROWS_WITH(makeTerrain(options), Catch::Contains("two points"));
    options = {};
    options.carves.push_back({{{0, 0}, {1, 0}}, 10, 10, 1, 12, std::nullopt});
    CHECK_THROWS_WITH(makeTerrain(options), Catch::Contains("wallRoughness"));
}

TEST_CASE("procedural sphere and box: closed and outward with the right size", "[mesh]")
{
    const TriangleMesh sphere = makeSphere({{1, 2, 3}, 2.0, 3});
    CHECK(sphere.triangleCount() == 20 * 64);
    CHECK(analyzeTopology(sphere).isClosed());
    CHECK(signedVolume(sphere) == Approx(4.0 / 3.0 * 3.14159265358979 * 8).epsilon(0.02));
    for (const Vec3f& p : sphere.points) CHECK((Vec3d(p) - Vec3d(1, 2, 3)).length() == Approx(2.0).epsilon(1e-6));

    const TriangleMesh box = makeBox({{0, 0, 0}, {2, 3, 4}});
    CHECK(analyzeTopology(box).isClosed());
    CHECK(signedVolume(box) == Approx(24.0));
    CHECK_THROWS_AS(makeBox({{0, 0, 0}, {0, 1, 1}}), ValueError);
    CHECK_THROWS_AS(makeSphere({{0, 0, 0}, -1.0, 1}), ValueError);
}

TEST_CASE("procedural terrain: ridged mountains have sharper crests than fBm hills, and erosion flattens valley floors", "[mesh]")
{
    // Curvature across the grid: the second difference of the heights, at
    // crests (local maxima along x) and in the lowest tenth of the ground.
    const auto profile = [](TerrainStyle style, double erosion) {
        TerrainSettings options;
        options.style = style;
        options.erosion = erosion;
        options.amplitude = 40;
        const int n = 400;
        std::vector<double> h(n);
        for (int i = 0; i < n; ++i) h[i] = terrainHeight(options, -100 + 200.0 * i / (n - 1), 13.0);
        double crest = 0.0, lowSlope = 0.0;
        int crests = 0, lows = 0;
        const double lowest = *std::min_element(h.begin(), h.end()), highest = *std::max_element(h.begin(), h.end());
        for (int i = 1; i + 1 < n; ++i) {
            if (h[i] > h[i - 1] && h[i] >= h[i + 1]) {
                crest += h[i - 1] + h[i + 1] - 2 * h[i];
                ++crests;
            }
            if (h[i] < lowest + 0.1 * (highest - lowest)) {
                lowSlope += std::abs(h[i + 1] - h[i - 1]);
                ++lows;
            }
        }
        return std::make_pair(crests ? crest / crests : 0.0, lows ? lowSlope / lows : 0.0);
    };
    const double hillCrest = profile(TerrainStyle::Fbm, 0.0).first;
    const auto [ridgeCrest, ridgeLow] = profile(TerrainStyle::Ridged, 0.0);
    const double erodedLow = profile(TerrainStyle::Ridged, 1.0).second;
    CHECK(ridgeCrest < 1.5 * hillCrest); // more negative: sharper
    CHECK(erodedLow < 0.7 * ridgeLow);
}

TEST_CASE("heightmap terrain: a 16-bit PNG's pixels become heights, corner to corner", "[mesh]")
{
    // 5 x 3 pixels, value = 1000 (x + 10 y): heights read back exactly, scaled.
    const std::string path = test::scratchDir("heightmap") + "/ramp.png";
    OIIO::ImageBuf image(OIIO::ImageSpec(5, 3, 1, OIIO::TypeDesc::UINT16));
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 5; ++x) {
            const float value = float(1000 * (x + 10 * y)) / 65535.0f;
            image.setpixel(x, y, &value);
        }
    REQUIRE(image.write(path, OIIO::TypeDesc::UINT16));
    HeightmapSettings options;
    options.path = path;
    options.sizeX = 40;
    options.sizeZ = 20;
    options.heightScale = 65.535; // a height of 1 per 1000 in the file
    const TriangleMesh terrain = makeHeightmapTerrain(options);
    CHECK(analyzeTopology(terrain).isClosed());
    CHECK(signedVolume(terrain) > 0.0);
    CHECK(terrain.triangleCount() == 2 * 4 * 2 + 6 * (4 + 2));
    // Grid point (i, k) at i * 3 + k: x = -20 + 10 i, z = -10 + 10 k, height i + 10 k.
    for (int i = 0; i < 5; ++i)
        for (int k = 0; k < 3; ++k) {
            const Vec3f p = terrain.points[std::size_t(i * 3 + k)];
            CHECK(p[0] == Approx(-20 + 10 * i));
            CHECK(p[2] == Approx(-10 + 10 * k));
            CHECK(p[1] == Approx(i + 10 * k).margin(1e-3));
        }
    // Twice the cells: the points between pixels are interpolated.
    options.cellsX = 8;
    options.cellsZ = 4;
    const TriangleMesh finer = makeHeightmapTerrain(options);
    CHECK(finer.points[std::size_t(1 * 5 + 1)][1] == Approx(0.5 + 5).margin(1e-3));

    options.path = path + ".missing.png";
    CHECK_THROWS_WITH(makeHeightmapTerrain(options), Catch::Contains(options.path));
}

namespace {

/// A 4 x 3 EXR heightmap of ones, with the given pixels changed.
std::string heightmapWith(const std::string& name, const std::vector<std::pair<std::pair<int, int>, float>>& pixels)
{
    const std::string path = test::scratchDir("heightmap-holes") + "/" + name + ".exr";
    OIIO::ImageBuf image(OIIO::ImageSpec(4, 3, 1, OIIO::TypeDesc::FLOAT));
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 4; ++x) {
            const float one = 1.0f + 0.1f * float(x);
            image.setpixel(x, y, &one);
        }
    for (const auto& [xy, value] : pixels) image.setpixel(xy.first, xy.second, &value);
    REQUIRE(image.write(path, OIIO::TypeDesc::FLOAT));
    return path;
}

} // namespace

TEST_CASE("heightmap terrain: pixels without a number are refused naming the first, or filled from their neighbours", "[mesh]")
{
    HeightmapSettings options;
    options.sizeX = options.sizeZ = 30;
    options.heightScale = 60;
    options.path = heightmapWith("holes", {{{2, 1}, std::nanf("")}, {{3, 2}, std::numeric_limits<float>::infinity()}});
    CHECK_THROWS_WITH(makeHeightmapTerrain(options), options.path +
                                                         ": pixel (2, 1) holds NaN, no height (elevation models "
                                                         "mark missing data so): set the heightmap's \"fillNoData\": "
                                                         "true to fill such pixels from their nearest valid neighbour");
    options.fillNoData = true;
    const TriangleMesh filled = makeHeightmapTerrain(options);
    for (const Vec3f& p : filled.points) REQUIRE(std::isfinite(p[1]));
    // Grid point (i, k) at i * 3 + k: each hole took a neighbour's height,
    // the first of its neighbours in the image's order.
    CHECK(filled.points[2 * 3 + 1][1] == Approx(60 * 1.2).epsilon(1e-5)); // from (2, 0)
    CHECK(filled.points[3 * 3 + 2][1] == Approx(60 * 1.3).epsilon(1e-5)); // from (3, 1)

    options.fillNoData = false;
    options.path = heightmapWith("absurd", {{{1, 0}, 1e30f}});
    CHECK_THROWS_WITH(makeHeightmapTerrain(options),
                      Catch::Contains(options.path + ": pixel (1, 0) is 1e+30, a height of 6e+31") &&
                          Catch::Contains("(at most +-1e+06)"));
    options.path = heightmapWith("valid", {});
    CHECK(analyzeTopology(makeHeightmapTerrain(options)).isClosed());
}
