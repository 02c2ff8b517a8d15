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
/// The sun depth map's density (two voxels a cell where it fits) and its
/// lattice stay within these many points, 32 and 16 MiB: a cloud spread over a
/// large box gets coarser shadows rather than a frame's memory.
constexpr std::size_t kMaxDepthDensityPoints = std::size_t(1) << 23, kMaxSunDepthPoints = std::size_t(1) << 22;

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
    mVoxelsPerCell = std::max(2, int(std::ceil(extent[mBounds.maxExtent()] / kLightGridResolution / voxel - 1e-9)));
    mFirstVoxel = active.min() - openvdb::Coord(1);
    const DenseGrid coarse = lightGridDensity();

    // Shadows on surfaces from a density as fine as fits, in cells of two voxels at best.
    int depthVoxelsPerCell = 2;
    while (depthVoxelsPerCell < mVoxelsPerCell &&
           latticeSize(latticePoints(extent, depthVoxelsPerCell * voxel)) > kMaxDepthDensityPoints)
        ++depthVoxelsPerCell;
    mSunDepth = depthVoxelsPerCell == mVoxelsPerCell
                    ? sunDepthTowardsSun(coarse)
                    : sunDepthTowardsSun(coarseDensity(*mDensity, mFirstVoxel, mBounds.min(),
                                                       latticePoints(extent, depthVoxelsPerCell * voxel), depthVoxelsPerCell));

    mSunVisible = DenseGrid(mBounds.min(), coarse.spacing(), coarse.points(), 1.0f, 1.0f);
    if (sunBlocked) // zero where a surface blocks the sun
        tbb::parallel_for(std::size_t(0), mSunVisible.size(), [&](std::size_t n) {
            const std::array<int, 3> ijk = mSunVisible.point(n);
            if (sunBlocked(mSunVisible.position(ijk[0], ijk[1], ijk[2]), mToSun)) mSunVisible[n] = 0.0f;
        });
}

DenseGrid CloudLighting::lightGridDensity() const
{
    const double cell = mVoxelsPerCell * mDensity->voxelSize()[0];
    return coarseDensity(*mDensity, mFirstVoxel, mBounds.min(), latticePoints(mBounds.extents(), cell), mVoxelsPerCell);
}

CloudLighting::SunDepth CloudLighting::sunDepthTowardsSun(const DenseGrid& density) const
{
    SunDepth map;
    const Vec3d& s = mToSun;
    map.across1 = (std::abs(s[1]) < 0.9 ? Vec3d(0, 1, 0) : Vec3d(1, 0, 0)).cross(s).unitSafe();
    map.across2 = s.cross(map.across1);
    map.centre = mBounds.getCenter();
    // The box's extent in the map's frame.
    Vec3d lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (int c = 0; c < 8; ++c) {
        const Vec3d d = boxCorner(mBounds, c) - map.centre;
        const Vec3d local(d.dot(map.across1), d.dot(map.across2), d.dot(s));
        lo = minComponent(lo, local);
        hi = maxComponent(hi, local);
    }
    map.acrossMin1 = lo[0];
    map.acrossMin2 = lo[1];
    map.top = hi[2];
    // Columns every half a density cell, slices every two cells, both
    // coarser together where the lattice would exceed its budget.
    double across = 0.5 * density.spacing(), along = 2.0 * density.spacing();
    std::array<int, 3> points;
    for (;; across *= 1.25, along *= 1.25) {
        points = {int(std::ceil((hi[0] - lo[0]) / across)) + 1, int(std::ceil((hi[1] - lo[1]) / across)) + 1,
                  int(std::ceil((hi[2] - lo[2]) / along)) + 1};
        if (latticeSize(points) <= kMaxSunDepthPoints) break;
    }
    map.inverseAcross = 1.0 / across;
    map.inverseAlong = 1.0 / along;
    map.depth = DenseGrid(Vec3d(0.0), 1.0, points, 0.0f, 0.0f);

    // Each column marched away from the sun through the box, in steps of at
    // most a density cell (half a cell changes a shadow by under 0.002), its
    // depth recorded at every slice.
    const double maxStep = density.spacing();
    const Vec3d away = -s;
    tbb::parallel_for(0, points[1], [&](int j) {
        for (int i = 0; i < points[0]; ++i) {
            const Vec3d origin = map.centre + map.across1 * (lo[0] + i * across) + map.across2 * (lo[1] + j * across) + s * hi[2];
            double tEnter = 0.0, tExit = (points[2] - 1) * along;
            if (!clip(origin, away, tEnter, tExit)) continue; // the column misses the cloud: depth 0
            double depth = 0.0, t = 0.0;
            for (int k = 1; k < points[2]; ++k) {
                const double from = std::max(t, tEnter), to = std::min(k * along, tExit);
                if (to > from) {
                    const int steps = int(std::ceil((to - from) / maxStep));
                    const double dt = (to - from) / steps;
                    for (int m = 0; m < steps; ++m) depth += density.at(origin + away * (from + (m + 0.5) * dt)) * dt;
                }
                t = k * along;
                map.depth[map.depth.index(i, j, k)] = float(depth);
            }
        }
    });
    return map;
}

double CloudLighting::SunDepth::at(const Vec3d& p, const Vec3d& toSun) const
{
    const Vec3d d = p - centre;
    const double column1 = (d.dot(across1) - acrossMin1) * inverseAcross, column2 = (d.dot(across2) - acrossMin2) * inverseAcross;
    const std::array<int, 3>& points = depth.points();
    if (!(column1 >= 0.0 && column2 >= 0.0 && column1 <= points[0] - 1 && column2 <= points[1] - 1)) return 0.0; // misses the box
    // Beyond the last slice (past the cloud, away from the sun) a point has
    // its column's whole depth; before the first, none.
    const double slice = std::clamp((top - d.dot(toSun)) * inverseAlong, 0.0, double(points[2] - 1));
    return std::max(0.0, double(depth.at(Vec3d(column1, column2, slice))));
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

bool CloudLighting::clip(const Vec3d& origin, const Vec3d& dir, double& tMin, double& tMax, double grow) const
{
    if (mEmpty) return false;
    const Vec3d lo = mBounds.min() - Vec3d(grow), hi = mBounds.max() + Vec3d(grow);
    for (int axis = 0; axis < 3; ++axis) {
        if (dir[axis] == 0.0) {
            if (origin[axis] < lo[axis] || origin[axis] > hi[axis]) return false;
            continue;
        }
        double t0 = (lo[axis] - origin[axis]) / dir[axis], t1 = (hi[axis] - origin[axis]) / dir[axis];
        if (t0 > t1) std::swap(t0, t1);
        tMin = std::max(tMin, t0);
        tMax = std::min(tMax, t1);
    }
    return tMin < tMax;
}

double CloudLighting::sunTransmittance(const Vec3d& p) const
{
    if (mEmpty) return 1.0;
    const double depth = mSunDepth.at(p, mToSun);
    return depth > 0.0 ? std::exp(-mExtinction * depth) : 1.0;
}

openvdb::FloatGrid::Ptr CloudLighting::skyLitDensity() const
{
    openvdb::FloatGrid::Ptr lit = mDensity->deepCopy();
    lit->setName("sky_lit_density");
    if (mEmpty) return lit;
    const DenseGrid skyTransmittance = transmittanceTowards(lightGridDensity(), Vec3d(0, 1, 0));
    const openvdb::math::Transform& transform = mDensity->transform();
    for (auto it = lit->beginValueOn(); it; ++it)
        it.setValue(float(*it * std::clamp(double(skyTransmittance.at(transform.indexToWorld(it.getCoord()))), 0.0, 1.0)));
    return lit;
}

} // namespace vfield
