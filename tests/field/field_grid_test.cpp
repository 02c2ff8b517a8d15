#include <vfield/field/field_grid.h>
#include <vfield/mesh/procedural.h>

#include <openvdb/tools/Interpolation.h>

#include <catch2/catch.hpp>

#include <array>
#include <map>
#include <random>

using namespace vfield;

namespace {

TriangleMesh smallTerrain()
{
    TerrainSettings options;
    options.cellsX = options.cellsZ = 48;
    options.carves.push_back({{{-100, 0}, {100, 10}}, 25.0, 15.0, 1.0, 0.0, std::nullopt});
    return makeTerrain(options);
}

} // namespace

TEST_CASE("field grid: nearest-voxel samples equal the octree's answer everywhere in the root", "[field][vdb]")
{
    const OctreeField field = OctreeField::build(smallTerrain());
    const FieldGrids grids = voxelizeField(field);
    REQUIRE(grids.force->getName() == "force");
    CHECK(grids.force->voxelSize()[0] == Approx(field.finestCellSize()));

    openvdb::tools::GridSampler<openvdb::Vec3SGrid, openvdb::tools::PointSampler> force(*grids.force);
    openvdb::tools::GridSampler<openvdb::Int32Grid, openvdb::tools::PointSampler> level(*grids.level);
    std::mt19937_64 random(7);
    const BBoxd& root = field.bounds();
    int mismatches = 0;
    for (int i = 0; i < 100000; ++i) {
        Vec3d p;
        for (int axis = 0; axis < 3; ++axis)
            p[axis] = root.min()[axis] + root.extents()[axis] * (double(random() >> 11) / double(1ull << 53));
        const FieldSample expected = field.sample(p);
        if (force.wsSample(p) != expected.force || level.wsSample(p) != expected.level) ++mismatches;
    }
    CHECK(mismatches == 0);
}

TEST_CASE("field grid: large leaves become tiles so memory follows the octree", "[field][vdb]")
{
    const OctreeField field = OctreeField::build(smallTerrain());
    const FieldGrids grids = voxelizeField(field);
    const double voxelsAcross = field.rootSide() / field.finestCellSize();
    CHECK(grids.force->activeVoxelCount() == openvdb::Index64(voxelsAcross * voxelsAcross * voxelsAcross));
    CHECK(grids.force->tree().activeTileCount() > 0);
    const double denseBytes = voxelsAcross * voxelsAcross * voxelsAcross * sizeof(openvdb::Vec3s);
    CHECK(double(grids.force->memUsage()) < 0.25 * denseBytes);
}

TEST_CASE("field grid: the surface grid marks exactly the leaves holding triangles", "[field][vdb]")
{
    const OctreeField field = OctreeField::build(smallTerrain());
    const FieldGrids grids = voxelizeField(field);
    uint64_t surfaceVoxels = 0;
    for (const FieldLeaf& leaf : field.leaves())
        if (leaf.isSurface) surfaceVoxels += uint64_t(leaf.width) * leaf.width * leaf.width;
    CHECK(grids.surface->activeVoxelCount() == surfaceVoxels);
}

TEST_CASE("field grid: the object's transform places the grid in the world", "[field][vdb]")
{
    const OctreeField field = OctreeField::build(makeSphere({{0, 0, 0}, 1.0, 2}));
    VoxelizeOptions options;
    options.worldFromObject.setToRotation(openvdb::math::Y_AXIS, 0.5);
    options.worldFromObject.postTranslate(Vec3d(10, -2, 3));
    const FieldGrids grids = voxelizeField(field, options);
    openvdb::tools::GridSampler<openvdb::Vec3SGrid, openvdb::tools::PointSampler> force(*grids.force);
    std::mt19937_64 random(3);
    int mismatches = 0;
    for (int i = 0; i < 2000; ++i) {
        Vec3d p;
        for (int axis = 0; axis < 3; ++axis) p[axis] = -1.15 + 2.3 * (double(random() >> 11) / double(1ull << 53));
        // The grid holds the object-space force, placed at the world position.
        if (force.wsSample(options.worldFromObject.transform(p)) != field.sample(p).force) ++mismatches;
    }
    CHECK(mismatches == 0);
}

TEST_CASE("field grid: the smooth grid holds each leaf's force at its centre, and averages leaves finer than its voxels",
          "[field][vdb]")
{
    // Deeper than the smooth grid goes: its voxels are the cells of level
    // kSmoothForceMaxLevel, and the leaves below take their average.
    OctreeFieldSettings options;
    options.maxLevel = kSmoothForceMaxLevel + 1;
    options.maxPerLeaf = 2;
    const OctreeField field = OctreeField::build(smallTerrain(), options);
    REQUIRE(field.depth() == kSmoothForceMaxLevel + 1);
    const openvdb::Vec3SGrid::Ptr smooth = smoothForceGrid(field);
    CHECK(smooth->voxelSize()[0] == Approx(field.cellSize(kSmoothForceMaxLevel)));

    const openvdb::Vec3SGrid::ConstAccessor forces = smooth->getConstAccessor();
    std::map<std::array<int, 3>, Vec3d> averages; // of the leaves finer than a voxel, per voxel
    int centres = 0, off = 0;
    for (const FieldLeaf& leaf : field.leaves()) {
        const int shift = field.depth() - kSmoothForceMaxLevel; // finest cells per voxel
        const std::array<int, 3> voxel{int(leaf.origin[0]) >> shift, int(leaf.origin[1]) >> shift, int(leaf.origin[2]) >> shift};
        if (leaf.level > kSmoothForceMaxLevel) {
            averages[voxel] += Vec3d(leaf.force) * std::ldexp(1.0, -3 * (leaf.level - kSmoothForceMaxLevel));
        } else if (leaf.level == kSmoothForceMaxLevel) {
            // A leaf of the grid's own level: its voxel holds its force.
            ++centres;
            if ((Vec3d(forces.getValue(openvdb::Coord(voxel[0], voxel[1], voxel[2]))) - Vec3d(leaf.force)).length() > 1e-6) ++off;
        }
    }
    int wrong = 0;
    for (const auto& [voxel, average] : averages)
        if ((Vec3d(forces.getValue(openvdb::Coord(voxel[0], voxel[1], voxel[2]))) - average).length() >
            1e-5 * std::max(1.0, average.length()))
            ++wrong;
    INFO(centres << " leaves of the grid's level, " << averages.size() << " voxels cut finer");
    CHECK(centres > 100);
    CHECK(averages.size() > 100);
    CHECK(off == 0);
    CHECK(wrong == 0);
}
