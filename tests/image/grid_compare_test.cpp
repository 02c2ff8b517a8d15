// OpenVDB files compared by content: voxel by voxel within a tolerance.

#include "test_meshes.h"

#include <vfield/core/error.h>
#include <vfield/core/vdb_file.h>
#include <vfield/image/grid_compare.h>
#include <vfield/volume/particle_grid.h>

#include <catch2/catch.hpp>

#include <algorithm>

using namespace vfield;

namespace {

openvdb::FloatGrid::Ptr density(float value, bool extraVoxel = false)
{
    openvdb::initialize();
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    grid->setName("density");
    grid->tree().setValue(openvdb::Coord(1, 2, 3), 1.0f);
    grid->tree().setValue(openvdb::Coord(4, 5, 6), value);
    if (extraVoxel) grid->tree().setValue(openvdb::Coord(9, 9, 9), 0.5f);
    return grid;
}

openvdb::Vec3SGrid::Ptr velocity(float x)
{
    openvdb::Vec3SGrid::Ptr grid = openvdb::Vec3SGrid::create();
    grid->setName("vel");
    grid->tree().setValue(openvdb::Coord(0, 0, 0), openvdb::Vec3s(x, 0, 0));
    return grid;
}

const GridDifference& named(const GridComparison& c, const std::string& name)
{
    const auto it = std::find_if(c.grids.begin(), c.grids.end(), [&](const GridDifference& g) { return g.name == name; });
    REQUIRE(it != c.grids.end());
    return *it;
}

} // namespace

TEST_CASE("grid compare: files of the same grids are equal", "[compare]")
{
    const std::string dir = test::scratchDir("grid-compare-same");
    writeVdb(dir + "/a.vdb", {density(2.0f), velocity(1.0f)});
    writeVdb(dir + "/b.vdb", {density(2.0f), velocity(1.0f)});
    const GridComparison c = compareGridFiles(dir + "/a.vdb", dir + "/b.vdb");
    CHECK(c.equal());
    CHECK(c.grids.size() == 2);
    CHECK(named(c, "density").voxels == 2);
}

TEST_CASE("grid compare: a voxel differing beyond the tolerance is counted with its size", "[compare]")
{
    const std::string dir = test::scratchDir("grid-compare-differ");
    writeVdb(dir + "/a.vdb", {density(2.0f), velocity(1.0f)});
    writeVdb(dir + "/b.vdb", {density(2.001f), velocity(1.5f)});
    const GridComparison exact = compareGridFiles(dir + "/a.vdb", dir + "/b.vdb");
    CHECK_FALSE(exact.equal());
    CHECK(named(exact, "density").differing == 1);
    CHECK(named(exact, "density").maxDifference == Approx(0.001).epsilon(1e-3));
    CHECK(named(exact, "vel").maxDifference == Approx(0.5)); // the length of the vector difference
    const GridComparison loose = compareGridFiles(dir + "/a.vdb", dir + "/b.vdb", 0.6);
    CHECK(loose.equal());
}

TEST_CASE("grid compare: a voxel active in one file only differs at any tolerance", "[compare]")
{
    const std::string dir = test::scratchDir("grid-compare-active");
    writeVdb(dir + "/a.vdb", {density(2.0f)});
    writeVdb(dir + "/b.vdb", {density(2.0f, true)});
    const GridComparison c = compareGridFiles(dir + "/a.vdb", dir + "/b.vdb", 10.0);
    CHECK_FALSE(c.equal());
    CHECK(named(c, "density").voxels == 3);
    CHECK(named(c, "density").differing == 1);
}

TEST_CASE("grid compare: grids in one file only are listed and make the files differ", "[compare]")
{
    const std::string dir = test::scratchDir("grid-compare-names");
    writeVdb(dir + "/a.vdb", {density(2.0f), velocity(1.0f)});
    writeVdb(dir + "/b.vdb", {density(2.0f)});
    const GridComparison c = compareGridFiles(dir + "/a.vdb", dir + "/b.vdb");
    CHECK_FALSE(c.equal());
    CHECK(c.onlyInA == std::vector<std::string>{"vel"});
    CHECK(c.onlyInB.empty());
}

TEST_CASE("grid compare: point grids compare by hash", "[compare]")
{
    const std::string dir = test::scratchDir("grid-compare-points");
    openvdb::initialize();
    // The particle grids vfield writes.
    const auto points = [](float x) {
        ParticleSet particles;
        for (const Vec3f& p : {Vec3f(x, 0, 0), Vec3f(0, 1, 0)}) {
            particles.position.push_back(p);
            particles.velocity.push_back(Vec3f(0.0f));
            particles.rest.push_back(p);
            particles.id.push_back(uint32_t(particles.id.size()));
            particles.radius.push_back(0.5f);
            particles.cloud.push_back(0);
        }
        openvdb::GridBase::Ptr grid = makeParticleGrid(particles);
        grid->setName("particles");
        return grid;
    };
    writeVdb(dir + "/a.vdb", {points(0.1f)});
    writeVdb(dir + "/b.vdb", {points(0.1f)});
    writeVdb(dir + "/c.vdb", {points(0.2f)});
    CHECK(compareGridFiles(dir + "/a.vdb", dir + "/b.vdb").equal());
    const GridComparison moved = compareGridFiles(dir + "/a.vdb", dir + "/c.vdb");
    CHECK_FALSE(moved.equal());
    CHECK(named(moved, "particles").comparedByHash);
}

TEST_CASE("grid compare: a missing file is an error naming it", "[compare]")
{
    const std::string dir = test::scratchDir("grid-compare-missing");
    writeVdb(dir + "/a.vdb", {density(2.0f)});
    CHECK_THROWS_AS(compareGridFiles(dir + "/a.vdb", dir + "/none.vdb"), FileError);
}
