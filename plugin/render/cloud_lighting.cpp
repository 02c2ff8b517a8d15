#include <vfield/render/cloud_lighting.h>

#include <openvdb/tools/Interpolation.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace vfield {

namespace {

/// The light transmittance grids have about this many voxels along their longest side.
constexpr double kLightGridResolution = 64.0;

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
    mSunTransmittance = transmittanceGrid(mToSun);
    mSunInCloud = sunBlocked ? withSurfaceShadows(*mSunTransmittance, mToSun, sunBlocked) : mSunTransmittance;
    mSkyTransmittance = transmittanceGrid(Vec3d(0, 1, 0));
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

openvdb::FloatGrid::Ptr CloudLighting::transmittanceGrid(const Vec3d& towards) const
{
    // At the centres of a coarse grid over the box, through the cloud towards the light.
    const Vec3d extent = mBounds.extents();
    const double cell = std::max(2.0 * mDensity->voxelSize()[0], extent[mBounds.maxExtent()] / kLightGridResolution);
    const openvdb::Coord cells(int(std::ceil(extent[0] / cell)) + 1, int(std::ceil(extent[1] / cell)) + 1,
                               int(std::ceil(extent[2] / cell)) + 1);
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(1.0f);
    auto transform = openvdb::math::Transform::createLinearTransform(cell);
    transform->postTranslate(mBounds.min());
    grid->setTransform(transform);

    std::vector<float> values(std::size_t(cells[0]) * cells[1] * cells[2]);
    const double step = 0.5 * cell;
    tbb::parallel_for(0, cells[2], [&](int k) {
        openvdb::FloatGrid::ConstAccessor accessor = mDensity->getConstAccessor();
        const openvdb::math::Transform& densityTransform = mDensity->transform();
        for (int j = 0; j < cells[1]; ++j)
            for (int i = 0; i < cells[0]; ++i) {
                const Vec3d p = transform->indexToWorld(openvdb::Coord(i, j, k));
                double tEnter = 0.0, tExit = std::numeric_limits<double>::max();
                float t = 1.0f;
                if (clip(p, towards, tEnter, tExit)) {
                    double opticalDepth = 0.0;
                    for (double s = tEnter + 0.5 * step; s < tExit; s += step) {
                        float rho;
                        openvdb::tools::BoxSampler::sample(accessor, densityTransform.worldToIndex(p + towards * s), rho);
                        opticalDepth += rho * step;
                    }
                    t = float(std::exp(-mExtinction * opticalDepth));
                }
                values[(std::size_t(k) * cells[1] + j) * cells[0] + i] = t;
            }
    });
    auto accessor = grid->getAccessor();
    for (int k = 0; k < cells[2]; ++k)
        for (int j = 0; j < cells[1]; ++j)
            for (int i = 0; i < cells[0]; ++i)
                accessor.setValue(openvdb::Coord(i, j, k), values[(std::size_t(k) * cells[1] + j) * cells[0] + i]);
    return grid;
}

openvdb::FloatGrid::Ptr CloudLighting::withSurfaceShadows(const openvdb::FloatGrid& transmittance, const Vec3d& towards,
                                                          const Occlusion& blocked)
{
    openvdb::FloatGrid::Ptr shadowed = transmittance.deepCopy();
    std::vector<openvdb::FloatTree::ValueOnIter> values;
    for (auto it = shadowed->tree().beginValueOn(); it; ++it) values.push_back(it);
    tbb::parallel_for(std::size_t(0), values.size(), [&](std::size_t i) {
        openvdb::FloatTree::ValueOnIter& it = values[i];
        if (blocked(shadowed->transform().indexToWorld(it.getCoord()), towards)) it.setValue(0.0f);
    });
    return shadowed;
}

double CloudLighting::sunTransmittance(const Vec3d& p) const
{
    if (mEmpty) return 1.0;
    double tMin = 0.0, tMax = std::numeric_limits<double>::max();
    if (!clip(p, mToSun, tMin, tMax)) return 1.0;
    // Outside the box, what matters is where the sun's ray enters it.
    const Vec3d q = mBounds.isInside(p) ? p : p + mToSun * tMin;
    const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sampler(*mSunTransmittance);
    return std::clamp(double(sampler.wsSample(q)), 0.0, 1.0);
}

openvdb::FloatGrid::Ptr CloudLighting::skyLitDensity() const
{
    openvdb::FloatGrid::Ptr lit = mDensity->deepCopy();
    lit->setName("sky_lit_density");
    if (mEmpty) return lit;
    const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sky(*mSkyTransmittance);
    const openvdb::math::Transform& transform = mDensity->transform();
    for (auto it = lit->beginValueOn(); it; ++it)
        it.setValue(float(*it * std::clamp(double(sky.wsSample(transform.indexToWorld(it.getCoord()))), 0.0, 1.0)));
    return lit;
}

} // namespace vfield
