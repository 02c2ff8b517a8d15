#include <vfield/render/cloud_lighting.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace vfield {

namespace {

/// The light transmittance grids have about this many cells along the box's longest side.
constexpr double kLightGridResolution = 64.0;

/// The density box-filtered onto cells of a whole number of its voxels from
/// `corner` (the lower corner of voxel `first`), values at the cells' centres:
/// all that a light grid of that resolution can resolve, in a plain array, so
/// that marches towards a light read it at a fraction of the cost of trilinear
/// reads of the tree (most of a frame's lookups).
DenseGrid coarseDensity(const openvdb::FloatGrid& density, const openvdb::Coord& first, const Vec3d& corner,
                        const std::array<int, 3>& cells, int voxelsPerCell)
{
    const double cell = density.voxelSize()[0] * voxelsPerCell;
    DenseGrid coarse(corner + Vec3d(0.5 * cell), cell, cells, 0.0f, 0.0f);
    const float perVoxel = 1.0f / float(voxelsPerCell * voxelsPerCell * voxelsPerCell);
    const auto cellOf = [&](const openvdb::Coord& c) {
        const openvdb::Coord n = c - first;
        return openvdb::Coord(n.x() / voxelsPerCell, n.y() / voxelsPerCell, n.z() / voxelsPerCell);
    };
    // Each task sums the voxels of its own x-slab of cells, leaves in tree
    // order: the sums are the same for any thread count.
    std::vector<const openvdb::FloatTree::LeafNodeType*> leaves;
    density.tree().getNodes(leaves);
    tbb::parallel_for(0, cells[0], [&](int slab) {
        for (const auto* leaf : leaves) {
            const openvdb::CoordBBox box = leaf->getNodeBoundingBox();
            if (cellOf(box.max()).x() < slab || cellOf(box.min()).x() > slab) continue;
            for (auto voxel = leaf->cbeginValueOn(); voxel; ++voxel) {
                const openvdb::Coord c = cellOf(voxel.getCoord());
                if (c.x() == slab) coarse[coarse.index(c.x(), c.y(), c.z())] += *voxel * perVoxel;
            }
        }
    });
    // Active tiles (a grid filled by hand has them; a splat has none): each
    // adds its value over the voxels it shares with each cell.
    auto tile = density.tree().cbeginValueOn();
    tile.setMaxDepth(openvdb::FloatTree::ValueOnCIter::LEAF_DEPTH - 1);
    for (; tile; ++tile) {
        const openvdb::CoordBBox box = tile.getBoundingBox();
        const openvdb::Coord from = cellOf(box.min()), to = cellOf(box.max());
        for (int i = std::max(0, from.x()); i <= std::min(to.x(), cells[0] - 1); ++i)
            for (int j = std::max(0, from.y()); j <= std::min(to.y(), cells[1] - 1); ++j)
                for (int k = std::max(0, from.z()); k <= std::min(to.z(), cells[2] - 1); ++k) {
                    const openvdb::Coord cellMin =
                        first + openvdb::Coord(i * voxelsPerCell, j * voxelsPerCell, k * voxelsPerCell);
                    openvdb::CoordBBox shared(cellMin, cellMin + openvdb::Coord(voxelsPerCell - 1));
                    shared.intersect(box);
                    coarse[coarse.index(i, j, k)] += *tile * perVoxel * float(shared.volume());
                }
    }
    return coarse;
}

} // namespace

CloudLighting::CloudLighting(openvdb::FloatGrid::ConstPtr density, const MediumSettings& medium, const Vec3d& toSun,
                             const Occlusion& sunBlocked)
    : mDensity(std::move(density)), mToSun(toSun.unitSafe()), mExtinction(medium.extinction)
{
    const openvdb::CoordBBox active = mDensity->evalActiveVoxelBoundingBox();
    if (active.empty() || mExtinction <= 0.0) return;
    mEmpty = false;
    const openvdb::BBoxd index(active.min().asVec3d() - 1.5, active.max().asVec3d() + 1.5);
    mBounds = mDensity->transform().indexToWorld(index);

    // Light grid points every `cell` from the box's corner, a cell a whole
    // number (at least two) of density voxels so that the coarse density's
    // cells tile them.
    const double voxel = mDensity->voxelSize()[0];
    const Vec3d extent = mBounds.extents();
    const int voxelsPerCell = std::max(2, int(std::ceil(extent[mBounds.maxExtent()] / kLightGridResolution / voxel - 1e-9)));
    const double cell = voxelsPerCell * voxel;
    const std::array<int, 3> points{int(std::ceil(extent[0] / cell)) + 1, int(std::ceil(extent[1] / cell)) + 1,
                                    int(std::ceil(extent[2] / cell)) + 1};
    const DenseGrid coarse = coarseDensity(*mDensity, active.min() - openvdb::Coord(1), mBounds.min(), points, voxelsPerCell);

    mSunTransmittance = transmittanceTowards(coarse, mToSun);
    mSunInCloud = mSunTransmittance;
    if (sunBlocked) // zero where a surface blocks the sun
        tbb::parallel_for(std::size_t(0), mSunInCloud.size(), [&](std::size_t n) {
            const std::array<int, 3> ijk = mSunInCloud.point(n);
            if (sunBlocked(mSunInCloud.position(ijk[0], ijk[1], ijk[2]), mToSun)) mSunInCloud[n] = 0.0f;
        });
    mSkyTransmittance = transmittanceTowards(coarse, Vec3d(0, 1, 0));
}

DenseGrid CloudLighting::transmittanceTowards(const DenseGrid& coarse, const Vec3d& towards) const
{
    // From each point through the cloud towards the light, a step of half a cell.
    DenseGrid transmittance(mBounds.min(), coarse.spacing(), coarse.points(), 1.0f, 1.0f);
    const double step = 0.5 * coarse.spacing();
    tbb::parallel_for(std::size_t(0), transmittance.size(), [&](std::size_t n) {
        const std::array<int, 3> ijk = transmittance.point(n);
        const Vec3d p = transmittance.position(ijk[0], ijk[1], ijk[2]);
        double tEnter = 0.0, tExit = std::numeric_limits<double>::max();
        if (!clip(p, towards, tEnter, tExit)) return;
        double opticalDepth = 0.0;
        for (double s = tEnter + 0.5 * step; s < tExit; s += step) opticalDepth += coarse.at(p + towards * s) * step;
        transmittance[n] = float(std::exp(-mExtinction * opticalDepth));
    });
    return transmittance;
}

bool CloudLighting::clip(const Vec3d& origin, const Vec3d& dir, double& tMin, double& tMax) const
{
    if (mEmpty) return false;
    for (int axis = 0; axis < 3; ++axis) {
        if (dir[axis] == 0.0) {
            if (origin[axis] < mBounds.min()[axis] || origin[axis] > mBounds.max()[axis]) return false;
            continue;
        }
        double t0 = (mBounds.min()[axis] - origin[axis]) / dir[axis], t1 = (mBounds.max()[axis] - origin[axis]) / dir[axis];
        if (t0 > t1) std::swap(t0, t1);
        tMin = std::max(tMin, t0);
        tMax = std::min(tMax, t1);
    }
    return tMin < tMax;
}

double CloudLighting::sunTransmittance(const Vec3d& p) const
{
    if (mEmpty) return 1.0;
    double tMin = 0.0, tMax = std::numeric_limits<double>::max();
    if (!clip(p, mToSun, tMin, tMax)) return 1.0;
    // Outside the box, what matters is where the sun's ray enters it.
    const Vec3d q = mBounds.isInside(p) ? p : p + mToSun * tMin;
    return std::clamp(double(mSunTransmittance.at(q)), 0.0, 1.0);
}

openvdb::FloatGrid::Ptr CloudLighting::skyLitDensity() const
{
    openvdb::FloatGrid::Ptr lit = mDensity->deepCopy();
    lit->setName("sky_lit_density");
    if (mEmpty) return lit;
    const openvdb::math::Transform& transform = mDensity->transform();
    for (auto it = lit->beginValueOn(); it; ++it)
        it.setValue(float(*it * std::clamp(double(mSkyTransmittance.at(transform.indexToWorld(it.getCoord()))), 0.0, 1.0)));
    return lit;
}

} // namespace vfield
