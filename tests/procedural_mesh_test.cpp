#include <vfield/core/error.h>
#include <vfield/mesh/procedural.h>

#include <catch2/catch.hpp>

using namespace vfield;

TEST_CASE("procedural terrain: a closed solid wound outward", "[mesh]")
{
    TerrainOptions options;
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
    TerrainOptions options;
    options.cellsX = options.cellsZ = 8;
    const TriangleMesh terrain = makeTerrain(options);
    // Grid point (i, k) is stored at i * (cellsZ + 1) + k.
    const Vec3f p = terrain.points[3 * 9 + 5];
    CHECK(p[0] == Approx(-100 + 200 * 3 / 8.0));
    CHECK(p[2] == Approx(-100 + 200 * 5 / 8.0));
    CHECK(p[1] == Approx(terrainHeight(options, p[0], p[2])).margin(1e-4));

    TerrainOptions other = options;
    other.seed = 2;
    CHECK(terrainHeight(options, 10, 20) == terrainHeight(options, 10, 20));
    CHECK(terrainHeight(options, 10, 20) != terrainHeight(other, 10, 20));
}

TEST_CASE("procedural terrain: a carve lowers its path by its depth and leaves the far ground alone", "[mesh]")
{
    TerrainOptions flat;
    flat.amplitude = 0.0;
    TerrainOptions carved = flat;
    carved.carves.push_back({{{-100, 0}, {0, 40}, {100, 0}}, 20.0, 12.0, 3.0});
    CHECK(terrainHeight(carved, -100, 0) == Approx(-12.0));
    CHECK(terrainHeight(carved, 0, 40) == Approx(-12.0));
    CHECK(terrainHeight(carved, 0, -60) == Approx(0.0));
    // A negative depth raises a ridge.
    carved.carves[0].depth = -8.0;
    CHECK(terrainHeight(carved, 100, 0) == Approx(8.0));
}

TEST_CASE("procedural terrain: options out of range are refused", "[mesh]")
{
    TerrainOptions options;
    options.cellsX = 0;
    CHECK_THROWS_AS(makeTerrain(options), ValueError);
    options = {};
    options.cellsX = options.cellsZ = 100000;
    CHECK_THROWS_WITH(makeTerrain(options), Catch::Contains("at most"));
    options = {};
    options.carves.push_back({{{0, 0}}, 10, 10, 1});
    CHECK_THROWS_WITH(makeTerrain(options), Catch::Contains("two points"));
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
