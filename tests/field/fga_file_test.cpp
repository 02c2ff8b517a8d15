#include "test_meshes.h"

#include <vfield/core/error.h>
#include <vfield/field/fga_file.h>
#include <vfield/mesh/procedural.h>

#include <catch2/catch.hpp>

#include <fstream>

using namespace vfield;

TEST_CASE("fga: cells are written x fastest after the size and the corners", "[fga]")
{
    // Each vector holds its own cell's indices, so the file's order shows.
    VectorGrid grid;
    grid.size = {3, 4, 5};
    grid.bounds = BBoxd(Vec3d(-1.5, 0.0, 2.0), Vec3d(1.5, 8.0, 12.0));
    for (int k = 0; k < 5; ++k)
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 3; ++i) grid.values.emplace_back(float(i), float(j), float(k));
    const std::string path = test::scratchDir("fga") + "/indices.fga";
    writeFga(path, grid);

    std::ifstream in(path);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    REQUIRE(lines.size() == 3 + 60);
    CHECK(lines[0] == "3,4,5,");
    CHECK(lines[1] == "-1.5,0,2,");
    CHECK(lines[2] == "1.5,8,12,");
    CHECK(lines[3] == "0,0,0,");
    CHECK(lines[4] == "1,0,0,");
    CHECK(lines[6] == "0,1,0,");
    CHECK(lines[3 + 12] == "0,0,1,");
    CHECK(lines.back() == "2,3,4,");

    const VectorGrid back = readFga(path);
    CHECK(back.size == grid.size);
    CHECK(back.bounds.min() == grid.bounds.min());
    CHECK(back.bounds.max() == grid.bounds.max());
    CHECK(back.values == grid.values);
    CHECK(grid.cellCenter(2, 0, 4)[0] == Approx(1.0));
    CHECK(grid.cellCenter(2, 0, 4)[2] == Approx(11.0));
}

TEST_CASE("fga: an octree field written and read back holds its force at every cell centre", "[fga]")
{
    SphereSettings sphere;
    sphere.subdivisions = 3;
    OctreeFieldSettings options;
    options.margin = 0.5;
    options.maxLevel = 5;
    const OctreeField field = OctreeField::build(makeSphere(sphere), options);
    const std::string path = test::scratchDir("fga") + "/sphere.fga";
    writeFga(path, sampleField(field, 16)); // the finest leaves' cells: 2^(5 - 1)
    const VectorGrid back = readFga(path);
    REQUIRE(back.values.size() == 16u * 16u * 16u);
    CHECK(back.bounds.min() == field.bounds().min());
    int nonZero = 0;
    for (int k = 0; k < 16; ++k)
        for (int j = 0; j < 16; ++j)
            for (int i = 0; i < 16; ++i) {
                const Vec3f expected = field.sample(back.cellCenter(i, j, k)).force;
                REQUIRE(back.values[std::size_t(i + 16 * (j + 16 * k))] == expected);
                if (expected.lengthSqr() > 0.0f) ++nonZero;
            }
    CHECK(nonZero == 16 * 16 * 16); // the root is full of field
}

TEST_CASE("fga: a truncated or malformed file is refused, naming it", "[fga]")
{
    const std::string dir = test::scratchDir("fga");
    std::ofstream(dir + "/short.fga") << "2,2,2,\n0,0,0,\n1,1,1,\n1,2,3,\n";
    CHECK_THROWS_WITH(readFga(dir + "/short.fga"), Catch::Contains("short.fga") && Catch::Contains("ends after 12 values"));
    std::ofstream(dir + "/word.fga") << "2,2,x,\n";
    CHECK_THROWS_WITH(readFga(dir + "/word.fga"), Catch::Contains("value 3 is not a number"));
    std::ofstream(dir + "/size.fga") << "0,2,2,\n";
    CHECK_THROWS_WITH(readFga(dir + "/size.fga"), Catch::Contains("grid size"));
}
