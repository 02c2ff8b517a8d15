#include <vfield/field/field_grid.h>

#include <vfield/core/error.h>

#include <tbb/parallel_for.h>

#include <cmath>

namespace vfield {

openvdb::GridPtrVec FieldGrids::all() const
{
    openvdb::GridPtrVec grids{force};
    if (level) grids.push_back(level);
    if (surface) grids.push_back(surface);
    return grids;
}

namespace {

/// The voxels (index space) whose centres lie in [min, max) of a leaf, for a
/// grid whose voxel (0,0,0) is centred half a voxel inside the root's min corner.
/// Centres sit half a voxel off any boundary the octree can have when the
/// voxel is the finest cell, so rounding of the boundaries cannot move a voxel.
openvdb::CoordBBox voxelsOf(const FieldLeaf& leaf, const Vec3d& rootMin, double voxelSize)
{
    openvdb::Coord lo, hi;
    for (int axis = 0; axis < 3; ++axis) {
        lo[axis] = int(std::ceil((leaf.bounds.min()[axis] - rootMin[axis]) / voxelSize - 0.5));
        hi[axis] = int(std::ceil((leaf.bounds.max()[axis] - rootMin[axis]) / voxelSize - 0.5)) - 1;
    }
    return openvdb::CoordBBox(lo, hi);
}

struct OctantTrees {
    openvdb::Vec3STree::Ptr force;
    openvdb::Int32Tree::Ptr level;
    openvdb::BoolTree::Ptr surface;
};

} // namespace

FieldGrids voxelizeField(const OctreeField& field, const VoxelizeOptions& options)
{
    const double voxelSize = options.voxelSize.value_or(field.finestCellSize());
    if (!(voxelSize > 0) || !std::isfinite(voxelSize)) throw ValueError("voxel size must be a positive number");
    const double voxelsAcross = field.rootSide() / voxelSize;
    if (voxelsAcross > double(1 << 24))
        throw ValueError("voxel size " + std::to_string(voxelSize) + " gives " + std::to_string(voxelsAcross) +
                         " voxels across the field (at most 2^24)");

    // The root's 8 octants cover disjoint voxels: voxelize them into separate
    // trees at once and merge; the result does not depend on the thread count.
    const Vec3d rootMin = field.bounds().min();
    OctantTrees octants[8];
    tbb::parallel_for(0, 8, [&](int octant) {
        OctantTrees& trees = octants[octant];
        trees.force = std::make_shared<openvdb::Vec3STree>(openvdb::Vec3s(0.0f));
        if (options.withLevel) trees.level = std::make_shared<openvdb::Int32Tree>(0);
        if (options.withSurface) trees.surface = std::make_shared<openvdb::BoolTree>(false);
        for (const FieldLeaf& leaf : field.leavesOfOctant(octant)) {
            const openvdb::CoordBBox voxels = voxelsOf(leaf, rootMin, voxelSize);
            if (voxels.empty()) continue; // a leaf thinner than a voxel holds no voxel centre
            // fill() writes tiles wherever a whole OpenVDB node is covered.
            trees.force->fill(voxels, leaf.force, true);
            if (trees.level) trees.level->fill(voxels, leaf.level, true);
            if (trees.surface && leaf.isSurface) trees.surface->fill(voxels, true, true);
        }
    });

    auto transform = openvdb::math::Transform::createLinearTransform(voxelSize);
    transform->postTranslate(rootMin + Vec3d(0.5 * voxelSize));
    if (options.worldFromObject != Mat4d::identity()) transform->postMult(options.worldFromObject);

    FieldGrids grids;
    grids.force = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    grids.force->setName("force");
    grids.force->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    if (options.withLevel) {
        grids.level = openvdb::Int32Grid::create(0);
        grids.level->setName("level");
    }
    if (options.withSurface) {
        grids.surface = openvdb::BoolGrid::create(false);
        grids.surface->setName("surface");
    }
    for (const OctantTrees& trees : octants) {
        grids.force->tree().merge(*trees.force);
        if (grids.level) grids.level->tree().merge(*trees.level);
        if (grids.surface) grids.surface->tree().merge(*trees.surface);
    }
    for (const openvdb::GridBase::Ptr& grid : grids.all()) {
        grid->setTransform(transform->copy());
        grid->insertMeta("vfield_octree_depth", openvdb::Int32Metadata(field.depth()));
    }
    return grids;
}

} // namespace vfield
