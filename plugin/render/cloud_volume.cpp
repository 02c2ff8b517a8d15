#include <vfield/render/cloud_volume.h>

#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/RayIntersector.h>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace vfield {

struct CloudVolume::EmptySpaceSkipper {
    using Intersector = openvdb::tools::VolumeRayIntersector<openvdb::FloatGrid>;
    explicit EmptySpaceSkipper(const openvdb::FloatGrid& grid)
        : master(grid, /*dilation for trilinear reads=*/1), perThread(master)
    {}
    Intersector master;
    tbb::enumerable_thread_specific<Intersector> perThread; ///< copies share the master's tree
};

double henyeyGreenstein(double cosTheta, double g)
{
    const double denominator = 1.0 + g * g - 2.0 * g * cosTheta;
    return (1.0 - g * g) / (4.0 * M_PI * denominator * std::sqrt(denominator));
}

namespace {

/// The light transmittance grids have about this many voxels along their longest side.
constexpr double kLightGridResolution = 48.0;

double sampleDensity(openvdb::FloatGrid::ConstAccessor& accessor, const openvdb::math::Transform& transform, const Vec3d& p)
{
    float value;
    openvdb::tools::BoxSampler::sample(accessor, transform.worldToIndex(p), value);
    return value;
}

} // namespace

bool CloudVolume::clip(const Vec3d& origin, const Vec3d& dir, double& tMin, double& tMax) const
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

CloudVolume::CloudVolume(openvdb::FloatGrid::ConstPtr density, const ImageSettings& image, const Vec3d& toSun,
                         const SurfaceScene* occluders)
    : mDensity(std::move(density)), mToSun(toSun.unitSafe()), mExtinction(image.extinction), mAlbedo(image.albedo),
      mAnisotropy(image.anisotropy), mStep(image.volumeStep)
{
    const openvdb::CoordBBox active = mDensity->evalActiveVoxelBoundingBox();
    if (active.empty() || mExtinction <= 0.0) return;
    mEmpty = false;
    // The box of the voxels' extents, one voxel wider so trilinear reads fade to zero inside it.
    const openvdb::BBoxd index(active.min().asVec3d() - 1.5, active.max().asVec3d() + 1.5);
    mBounds = mDensity->transform().indexToWorld(index);

    mSunTransmittance = transmittanceGrid(mToSun, occluders);
    mSkyTransmittance = transmittanceGrid(Vec3d(0, 1, 0), nullptr);
    if (image.skipEmptySpace) mSkipper = std::make_shared<EmptySpaceSkipper>(*mDensity);
}

openvdb::FloatGrid::Ptr CloudVolume::transmittanceGrid(const Vec3d& towards, const SurfaceScene* occluders) const
{
    // At the centres of a coarse grid over the box: through the cloud towards
    // the light, and zero where a surface blocks it.
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
        for (int j = 0; j < cells[1]; ++j)
            for (int i = 0; i < cells[0]; ++i) {
                const Vec3d p = transform->indexToWorld(openvdb::Coord(i, j, k));
                double tEnter = 0.0, tExit = std::numeric_limits<double>::max();
                float t = 1.0f;
                if (occluders && occluders->occluded(p, towards, 1e-3, std::numeric_limits<double>::max())) {
                    t = 0.0f;
                } else if (clip(p, towards, tEnter, tExit)) {
                    double opticalDepth = 0.0;
                    for (double s = tEnter + 0.5 * step; s < tExit; s += step)
                        opticalDepth += sampleDensity(accessor, mDensity->transform(), p + towards * s) * step;
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

double CloudVolume::sunTransmittance(const Vec3d& p) const
{
    if (mEmpty) return 1.0;
    double tMin = 0.0, tMax = std::numeric_limits<double>::max();
    if (!clip(p, mToSun, tMin, tMax)) return 1.0;
    // Outside the box, what matters is where the sun's ray enters it.
    const Vec3d q = mBounds.isInside(p) ? p : p + mToSun * tMin;
    const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sampler(*mSunTransmittance);
    return std::clamp(double(sampler.wsSample(q)), 0.0, 1.0);
}

openvdb::FloatGrid::Ptr CloudVolume::skyLitDensity() const
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

CloudVolume::Segment CloudVolume::march(const Vec3d& origin, const Vec3d& dir, double tMin, double tMax, double jitter,
                                        const Vec3d& sunRadiance, const Vec3d& skyRadiance) const
{
    Segment segment;
    if (!clip(origin, dir, tMin, tMax)) return segment;
    openvdb::FloatGrid::ConstAccessor density = mDensity->getConstAccessor();
    openvdb::FloatGrid::ConstAccessor sun = mSunTransmittance->getConstAccessor();
    openvdb::FloatGrid::ConstAccessor sky = mSkyTransmittance->getConstAccessor();
    const openvdb::math::Transform& densityTransform = mDensity->transform();
    const openvdb::math::Transform& lightTransform = mSunTransmittance->transform(); // both grids share it
    // Sunlight travels along -toSun and leaves towards the origin along -dir:
    // the angle between the two is that between dir and toSun.
    const double phase = henyeyGreenstein(dir.dot(mToSun), mAnisotropy);
    const Vec3d sunScatter = sunRadiance * phase;

    // Stratified: each step covers [t, t + dt) and samples it at a jittered point.
    const auto marchInterval = [&](double from, double to) {
        for (double t = from; t < to && segment.transmittance > 0.0; t += mStep) {
            const double dt = std::min(mStep, to - t);
            const Vec3d p = origin + dir * (t + jitter * dt);
            const double rho = sampleDensity(density, densityTransform, p);
            if (rho <= 0.0) continue;
            const double stepTransmittance = std::exp(-mExtinction * rho * dt);
            const openvdb::Vec3d index = lightTransform.worldToIndex(p);
            float sunT, skyT;
            openvdb::tools::BoxSampler::sample(sun, index, sunT);
            openvdb::tools::BoxSampler::sample(sky, index, skyT);
            // In-scattered light of the step, integrated exactly for constant density:
            // (1 - e^(-sigma_t dt)) * albedo * source. The sky lights the cloud
            // through the cloud above it, so bases darken and tops stay bright.
            const Vec3d source =
                sunScatter * std::clamp(double(sunT), 0.0, 1.0) + skyRadiance * std::clamp(double(skyT), 0.0, 1.0);
            segment.radiance += segment.transmittance * (1.0 - stepTransmittance) * mAlbedo * source;
            segment.transmittance *= stepTransmittance;
            if (segment.transmittance < 1e-3) segment.transmittance = 0.0;
        }
    };
    if (!mSkipper) {
        marchInterval(tMin, tMax);
        return segment;
    }
    // Only the spans of nodes that hold density; index-space times scale by the voxel size.
    EmptySpaceSkipper::Intersector& intersector = mSkipper->perThread.local();
    const double voxel = mDensity->voxelSize()[0];
    if (!intersector.setWorldRay(openvdb::math::Ray<double>(origin, dir, tMin, tMax))) return segment;
    double t0 = 0.0, t1 = 0.0;
    while (segment.transmittance > 0.0 && intersector.march(t0, t1))
        marchInterval(std::max(tMin, t0 * voxel), std::min(tMax, t1 * voxel));
    return segment;
}

} // namespace vfield
