#include <vfield/field/field_grid.h>

#include <vfield/core/error.h>

#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>

#include <tbb/parallel_for.h>

#include <algorithm>
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

/// A dense lattice of forces at the cell centres of one octree level, x
/// fastest, each with the level whose lattice it was interpolated from (its
/// own level where a node of this level lies).
class Lattice {
public:
    explicit Lattice(int level)
        : mSide(1 << (level - 1)), mForces(std::size_t(mSide) * mSide * mSide), mSources(mForces.size(), uint8_t(level))
    {}
    int side() const { return mSide; }
    std::size_t index(int i, int j, int k) const { return (std::size_t(k) * mSide + j) * mSide + i; }
    Vec3f& force(std::size_t index) { return mForces[index]; }
    uint8_t& source(std::size_t index) { return mSources[index]; }
    uint8_t source(std::size_t index) const { return mSources[index]; }

    /// Trilinear between the centres around `p` (cell units of this level:
    /// cell i's centre at i); beyond the outermost centres the force stays
    /// at theirs. `corners` receives the 8 centres read.
    Vec3f interpolate(const double p[3], std::size_t corners[8]) const
    {
        int lo[3], hi[3];
        float weight[3];
        for (int axis = 0; axis < 3; ++axis) {
            const double floor = std::floor(p[axis]);
            weight[axis] = float(p[axis] - floor);
            lo[axis] = std::clamp(int(floor), 0, mSide - 1);
            hi[axis] = std::clamp(int(floor) + 1, 0, mSide - 1);
        }
        Vec3f sum(0.0f);
        for (int corner = 0; corner < 8; ++corner) {
            const bool x = corner & 1, y = corner & 2, z = corner & 4;
            corners[corner] = index(x ? hi[0] : lo[0], y ? hi[1] : lo[1], z ? hi[2] : lo[2]);
            const float w =
                (x ? weight[0] : 1.0f - weight[0]) * (y ? weight[1] : 1.0f - weight[1]) * (z ? weight[2] : 1.0f - weight[2]);
            sum += mForces[corners[corner]] * w;
        }
        return sum;
    }

private:
    int mSide;
    std::vector<Vec3f> mForces;
    std::vector<uint8_t> mSources;
};

/// The force at cell (i, j, k) of `level` where no node of that level lies
/// (inside a coarser leaf), from the coarser lattices (lattices[l - 1] is
/// level l's): trilinear between the level above's centres; where those were
/// all interpolated from one level's lattice, straight from that lattice, so
/// that the force stays that level's trilinear interpolant exactly (chained
/// interpolation would round its kinks off at every level).
Vec3f inherited(const std::vector<Lattice>& lattices, int level, const int cell[3], uint8_t& source)
{
    // Cell c's centre in the cell units of level l: (c + 0.5) 2^(l - level) - 0.5.
    const auto position = [&](int l, double p[3]) {
        for (int axis = 0; axis < 3; ++axis) p[axis] = (cell[axis] + 0.5) * std::ldexp(1.0, l - level) - 0.5;
    };
    const Lattice& above = lattices[std::size_t(level - 2)];
    double p[3];
    position(level - 1, p);
    std::size_t corners[8];
    const Vec3f fromAbove = above.interpolate(p, corners);
    source = above.source(corners[0]);
    for (const std::size_t corner : corners)
        if (above.source(corner) != source) {
            source = uint8_t(level - 1);
            return fromAbove;
        }
    position(source, p);
    return lattices[std::size_t(source - 1)].interpolate(p, corners);
}

} // namespace

openvdb::Vec3SGrid::Ptr smoothForceGrid(const OctreeField& field)
{
    const int finest = std::min(field.depth(), kSmoothForceMaxLevel);
    const std::vector<FieldLeaf> nodes = field.nodes();
    // A node's cell at its own level, from its origin in cells of depth().
    const auto cellOf = [&field](const FieldLeaf& node, int axis) {
        return int(node.origin[axis] >> (field.depth() - node.level));
    };

    // Coarse to fine, every level but the finest as a dense lattice: at most
    // 128^3 forces (25 MB) and 1/7 of that for all coarser ones.
    std::vector<Lattice> lattices;
    for (int level = 1; level < finest; ++level) {
        Lattice lattice(level);
        if (level > 1)
            tbb::parallel_for(0, lattice.side(), [&](int k) {
                for (int j = 0; j < lattice.side(); ++j)
                    for (int i = 0; i < lattice.side(); ++i) {
                        const int cell[3] = {i, j, k};
                        const std::size_t at = lattice.index(i, j, k);
                        lattice.force(at) = inherited(lattices, level, cell, lattice.source(at));
                    }
            });
        for (const FieldLeaf& node : nodes)
            if (node.level == level) {
                const std::size_t at = lattice.index(cellOf(node, 0), cellOf(node, 1), cellOf(node, 2));
                lattice.force(at) = node.force;
                lattice.source(at) = uint8_t(level);
            }
        lattices.push_back(std::move(lattice));
    }

    // The finest level straight into the grid's voxels.
    const int side = 1 << (finest - 1);
    openvdb::Vec3SGrid::Ptr grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    grid->tree().fill(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(side - 1)), openvdb::Vec3s(0.0f), true);
    grid->tree().voxelizeActiveTiles();
    if (finest > 1) {
        openvdb::tree::LeafManager<openvdb::Vec3STree> leaves(grid->tree());
        leaves.foreach ([&](openvdb::Vec3STree::LeafNodeType& leaf, std::size_t) {
            for (auto it = leaf.beginValueOn(); it; ++it) {
                const openvdb::Coord ijk = it.getCoord();
                const int cell[3] = {ijk.x(), ijk.y(), ijk.z()};
                uint8_t source;
                it.setValue(inherited(lattices, finest, cell, source));
            }
        });
    }
    openvdb::Vec3SGrid::Accessor forces = grid->getAccessor();
    for (const FieldLeaf& node : nodes) {
        if (node.level > finest) { // below the grid's resolution: its share of its cell's average
            const int shift = node.level - finest;
            const openvdb::Coord cell(cellOf(node, 0) >> shift, cellOf(node, 1) >> shift, cellOf(node, 2) >> shift);
            if (node.isLeaf) forces.setValue(cell, forces.getValue(cell) + node.force * std::ldexp(1.0f, -3 * shift));
            continue;
        }
        if (node.level != finest) continue;
        const openvdb::Coord cell(cellOf(node, 0), cellOf(node, 1), cellOf(node, 2));
        // A cell cut finer starts from nothing and sums its leaves' shares (nodes come before their children).
        forces.setValue(cell, node.isLeaf ? openvdb::Vec3s(node.force) : openvdb::Vec3s(0.0f));
    }
    openvdb::tools::prune(grid->tree());

    auto transform = openvdb::math::Transform::createLinearTransform(field.cellSize(finest));
    transform->postTranslate(field.bounds().min() + Vec3d(0.5 * field.cellSize(finest)));
    grid->setTransform(transform);
    grid->setName("force");
    grid->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    return grid;
}

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
