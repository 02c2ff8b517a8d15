#include <vfield/core/trilinear_sampler.h>

#include <openvdb/tools/Interpolation.h>

#include <catch2/catch.hpp>

#include <cmath>
#include <random>

using namespace vfield;

namespace {

/// Leaves of random values beside each other (reads across their faces), a
/// constant tile (reads from a node without leaves) with a leaf against it,
/// and the background around them, at negative and positive coordinates.
template<typename GridT, typename MakeValue>
typename GridT::Ptr patchworkGrid(MakeValue makeValue)
{
    auto grid = GridT::create(makeValue(0.0));
    std::mt19937_64 random(11);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    auto accessor = grid->getAccessor();
    for (const openvdb::CoordBBox& box :
         {openvdb::CoordBBox({-8, -8, -8}, {8, 11, 7}), openvdb::CoordBBox({20, 3, -30}, {27, 9, -25}),
          openvdb::CoordBBox({120, 2, 2}, {127, 6, 6})})
        for (auto c = box.begin(); c; ++c) accessor.setValueOn(*c, makeValue(unit(random)));
    grid->tree().addTile(/*level=*/1, openvdb::Coord(128, 0, 0), makeValue(0.75), /*active=*/true);
    return grid;
}

template<typename GridT>
void requireSameAsBoxSampler(const GridT& grid)
{
    TrilinearSampler<typename GridT::TreeType> sampler(grid.tree());
    const auto accessor = grid.getConstAccessor();
    std::mt19937_64 random(5);
    // Points within and around the leaves, the tile's box and the background between.
    const std::vector<openvdb::BBoxd> regions{{{-12, -12, -12}, {12, 14, 12}},
                                              {{18, 1, -32}, {30, 12, -22}},
                                              {{120, -4, -4}, {150, 20, 20}},
                                              {{-40, -40, -40}, {160, 40, 40}}};
    for (const openvdb::BBoxd& region : regions) {
        std::uniform_real_distribution<double> x(region.min()[0], region.max()[0]), y(region.min()[1], region.max()[1]),
            z(region.min()[2], region.max()[2]);
        for (int n = 0; n < 20000; ++n) {
            const openvdb::Vec3d p(x(random), y(random), z(random));
            typename GridT::ValueType expected;
            openvdb::tools::BoxSampler::sample(accessor, p, expected);
            const auto actual = sampler.atIndex(p);
            INFO("at " << p);
            REQUIRE(actual == expected);
        }
    }
    // Marches, as a ray's reads come: short steps in one direction, through
    // each leaf's last layer into the next leaves, a tile and the background.
    std::uniform_real_distribution<double> coordinate(-12.0, 12.0), unit(-1.0, 1.0);
    for (int ray = 0; ray < 400; ++ray) {
        openvdb::Vec3d p(coordinate(random), coordinate(random), coordinate(random));
        if (ray % 4 == 3) p += openvdb::Vec3d(124, 0, 0); // around the leaf against the tile
        const openvdb::Vec3d step = openvdb::Vec3d(unit(random), unit(random), unit(random)) * 0.3;
        for (int n = 0; n < 100; ++n, p += step) {
            typename GridT::ValueType expected;
            openvdb::tools::BoxSampler::sample(accessor, p, expected);
            const auto actual = sampler.atIndex(p);
            INFO("along a march at " << p);
            REQUIRE(actual == expected);
            // A voxel read between trilinear ones, from the leaf they keep.
            const openvdb::Coord voxel = openvdb::Coord::round(p);
            REQUIRE(sampler.valueAt(voxel) == accessor.getValue(voxel));
        }
    }
}

template<typename GridT>
void requireVoxelsAsAccessor(const GridT& grid)
{
    TrilinearSampler<typename GridT::TreeType> sampler(grid.tree());
    const auto accessor = grid.getConstAccessor();
    std::mt19937_64 random(7);
    std::uniform_int_distribution<int> x(-40, 160), yz(-12, 40);
    // Runs of neighbours along each axis from random voxels: through the
    // leaves and across their faces, into the tile and the background.
    for (int run = 0; run < 3000; ++run) {
        openvdb::Coord ijk(x(random), yz(random), yz(random));
        const openvdb::Coord step(run % 3 == 0, run % 3 == 1, run % 3 == 2);
        for (int n = 0; n < 20; ++n, ijk += step) {
            INFO("at " << ijk);
            REQUIRE(sampler.valueAt(ijk) == accessor.getValue(ijk));
        }
    }
}

} // namespace

TEST_CASE("trilinear sampler: reads what BoxSampler reads, bit for bit, inside leaves, across them, in tiles and the background",
          "[core]")
{
    SECTION("float")
    {
        requireSameAsBoxSampler(*patchworkGrid<openvdb::FloatGrid>([](double v) { return float(v); }));
    }
    SECTION("vector")
    {
        requireSameAsBoxSampler(
            *patchworkGrid<openvdb::Vec3SGrid>([](double v) { return openvdb::Vec3s(float(v), float(2.0 * v), float(v * v)); }));
    }
}

TEST_CASE("trilinear sampler: reads one voxel as the tree's accessor does, in leaves, a tile and the background", "[core]")
{
    SECTION("float")
    {
        requireVoxelsAsAccessor(*patchworkGrid<openvdb::FloatGrid>([](double v) { return float(v); }));
    }
    SECTION("integer, as the octree's levels")
    {
        requireVoxelsAsAccessor(*patchworkGrid<openvdb::Int32Grid>([](double v) { return int(std::lround(1000.0 * v)); }));
    }
}
