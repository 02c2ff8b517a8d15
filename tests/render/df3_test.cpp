// POV-Ray's density files: df3 export and reading back.

#include "test_meshes.h"

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>
#include <vfield/render/povray/df3.h>

#include <catch2/catch.hpp>

#include <openvdb/tools/Interpolation.h>

#include <cmath>
#include <random>

using namespace vfield;

namespace {

/// A lumpy cloud: random densities in a ball of radius 6 voxels, at voxel size 0.5.
openvdb::FloatGrid::Ptr lumpyCloud()
{
    openvdb::initialize();
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
    grid->transform().postTranslate(Vec3d(3.0, 4.0, -2.0));
    std::mt19937 random(5);
    std::uniform_real_distribution<float> value(0.0f, 3.7f);
    auto accessor = grid->getAccessor();
    for (int z = -6; z <= 6; ++z)
        for (int y = -6; y <= 6; ++y)
            for (int x = -6; x <= 6; ++x)
                if (x * x + y * y + z * z <= 36) accessor.setValue(openvdb::Coord(x, y, z), value(random));
    return grid;
}

} // namespace

TEST_CASE("df3: an export reads back as the grid within 16-bit quantization", "[df3]")
{
    const openvdb::FloatGrid::Ptr grid = lumpyCloud();
    const std::string dir = test::scratchDir("df3");
    const Df3Placement placement = writeDf3(*grid, dir + "/cloud.df3");
    const Df3Volume volume = readDf3(dir + "/cloud.df3");

    // The active box (13 voxels a side) and one empty cell on each side.
    REQUIRE(volume.nx == 15);
    REQUIRE(volume.ny == 15);
    REQUIRE(volume.nz == 15);
    CHECK(placement.cellSize == 0.5);
    // POV-Ray puts sample i at i/n of the cube: the cube starts at sample 0,
    // the empty voxel before the active box (index -7), and ends a cell past the last.
    CHECK(placement.worldBounds.min().eq(Vec3d(3.0 - 7 * 0.5, 4.0 - 7 * 0.5, -2.0 - 7 * 0.5)));
    CHECK(placement.worldBounds.max().eq(Vec3d(3.0 + 8 * 0.5, 4.0 + 8 * 0.5, -2.0 + 8 * 0.5)));

    auto accessor = grid->getConstAccessor();
    double worst = 0.0;
    for (int z = 0; z < volume.nz; ++z)
        for (int y = 0; y < volume.ny; ++y)
            for (int x = 0; x < volume.nx; ++x) {
                const double read = volume.at(x, y, z) / 65535.0 * placement.densityScale;
                worst = std::max(worst, std::abs(read - accessor.getValue(openvdb::Coord(x - 7, y - 7, z - 7))));
            }
    const double step = placement.densityScale / 65535.0;
    INFO("df3 round trip: largest error " << worst << " = " << worst / step << " of a 16-bit step (density scale "
                                          << placement.densityScale << ")");
    CHECK(worst <= 0.5 * step * (1.0 + 1e-6));
}

TEST_CASE("df3: a grid too large for maxResolution samples it on coarser cells", "[df3]")
{
    const openvdb::FloatGrid::Ptr grid = lumpyCloud();
    const std::string dir = test::scratchDir("df3-coarse");
    const Df3Placement placement = writeDf3(*grid, dir + "/cloud.df3", 8);
    const Df3Volume volume = readDf3(dir + "/cloud.df3");
    CHECK(volume.nx == 8); // 15 cells at a factor of 2
    CHECK(placement.cellSize == 1.0);
    // Sample 0 at the centre of the first 2-voxel cell, index -7.5 + 1.
    CHECK(placement.worldBounds.min().eq(Vec3d(3.0 - 6.5 * 0.5, 4.0 - 6.5 * 0.5, -2.0 - 6.5 * 0.5)));
    const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sampler(*grid);
    for (int x = 0; x < volume.nx; ++x) {
        const Vec3d centre = placement.worldBounds.min() + Vec3d(x, 3, 4) * placement.cellSize;
        CHECK(volume.at(x, 3, 4) / 65535.0 * placement.densityScale ==
              Approx(sampler.wsSample(centre)).margin(placement.densityScale / 65535.0));
    }
}

TEST_CASE("df3: a broken df3 file is an error naming it", "[df3]")
{
    const std::string dir = test::scratchDir("df3-bad");
    writeTextAtomically(dir + "/short.df3", std::string("\x00\x02\x00\x02\x00\x02\x01", 7));
    CHECK_THROWS_WITH(readDf3(dir + "/short.df3"), dir + "/short.df3: holds 1 bytes of samples for 2x2x2 cells");
    CHECK_THROWS_AS(readDf3(dir + "/missing.df3"), FileError);
}
