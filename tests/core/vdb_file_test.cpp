#include "test_meshes.h"

#include <vfield/core/error.h>
#include <vfield/core/vdb_file.h>
#include <vfield/field/field_grid.h>
#include <vfield/mesh/procedural.h>

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

using namespace vfield;

TEST_CASE("vdb file: grids read back with the same checksum though each file has its own id", "[vdb]")
{
    const std::string dir = test::scratchDir("vdb-roundtrip");
    const FieldGrids grids = voxelizeField(OctreeField::build(makeSphere({})));
    writeVdb(dir + "/a.vdb", grids.all());
    writeVdb(dir + "/b.vdb", grids.all());
    const openvdb::GridPtrVec a = readVdb(dir + "/a.vdb"), b = readVdb(dir + "/b.vdb");
    REQUIRE(a.size() == 3);
    for (std::size_t i = 0; i < a.size(); ++i) {
        CHECK(gridChecksum(*a[i]) == gridChecksum(*grids.all()[i]));
        CHECK(gridChecksum(*a[i]) == gridChecksum(*b[i]));
    }
    // The files themselves differ (random ids), so bytes are no test.
    std::ifstream fa(dir + "/a.vdb", std::ios::binary), fb(dir + "/b.vdb", std::ios::binary);
    const std::string bytesA((std::istreambuf_iterator<char>(fa)), {}), bytesB((std::istreambuf_iterator<char>(fb)), {});
    CHECK(bytesA != bytesB);
    // No temporary is left behind.
    CHECK(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()) == 2);
}

TEST_CASE("vdb file: the checksum changes with one voxel's value or the transform", "[vdb]")
{
    const FieldGrids grids = voxelizeField(OctreeField::build(makeSphere({})));
    const uint64_t original = gridChecksum(*grids.force);
    openvdb::Vec3SGrid::Ptr changed = grids.force->deepCopy();
    changed->tree().setValue(openvdb::Coord(3, 4, 5), openvdb::Vec3s(0, 0, 1e-6f));
    CHECK(gridChecksum(*changed) != original);
    openvdb::Vec3SGrid::Ptr moved = grids.force->deepCopy();
    moved->transform().postTranslate(Vec3d(0, 0, 1e-9));
    CHECK(gridChecksum(*moved) != original);
}

TEST_CASE("vdb file: summary gives voxel size and active voxels and world bounds", "[vdb]")
{
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    grid->setName("density");
    grid->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
    grid->tree().setValue(openvdb::Coord(0, 0, 0), 1.0f);
    grid->tree().setValue(openvdb::Coord(3, 1, 2), 1.0f);
    const GridSummary s = summarizeGrid(*grid);
    CHECK(s.name == "density");
    CHECK(s.type == "float");
    CHECK(s.activeVoxels == 2);
    CHECK(s.worldBounds.min() == Vec3d(-0.25, -0.25, -0.25));
    CHECK(s.worldBounds.max() == Vec3d(1.75, 0.75, 1.25));
}

TEST_CASE("vdb file: missing or corrupt or empty files are refused with their path", "[vdb]")
{
    const std::string dir = test::scratchDir("vdb-bad");
    CHECK_THROWS_WITH(readVdb(dir + "/missing.vdb"), Catch::StartsWith(dir + "/missing.vdb: "));
    std::ofstream(dir + "/junk.vdb") << "this is not an OpenVDB file";
    CHECK_THROWS_WITH(readVdb(dir + "/junk.vdb"), Catch::StartsWith(dir + "/junk.vdb: "));
    writeVdb(dir + "/none.vdb", {});
    CHECK_THROWS_WITH(readVdb(dir + "/none.vdb"), Catch::Contains("no grid"));
}
