#include <vfield/render/embree/cloud_volume.h>

#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/RayIntersector.h>

#include <tbb/enumerable_thread_specific.h>

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

double sampleDensity(openvdb::FloatGrid::ConstAccessor& accessor, const openvdb::math::Transform& transform, const Vec3d& p)
{
    float value;
    openvdb::tools::BoxSampler::sample(accessor, transform.worldToIndex(p), value);
    return value;
}

} // namespace

CloudVolume::CloudVolume(const CloudLighting& lighting, const MediumSettings& medium, const IntegratorSettings& integrator)
    : mLighting(lighting), mExtinction(medium.extinction), mAlbedo(medium.albedo), mAnisotropy(medium.anisotropy),
      mStep(integrator.volumeStep)
{
    if (!lighting.empty() && integrator.skipEmptySpace) mSkipper = std::make_shared<EmptySpaceSkipper>(lighting.density());
}

CloudVolume::Segment CloudVolume::march(const Vec3d& origin, const Vec3d& dir, double tMin, double tMax, double jitter,
                                        const Vec3d& sunRadiance, const Vec3d& skyRadiance) const
{
    Segment segment;
    if (!mLighting.clip(origin, dir, tMin, tMax)) return segment;
    const openvdb::FloatGrid& densityGrid = mLighting.density();
    openvdb::FloatGrid::ConstAccessor density = densityGrid.getConstAccessor();
    openvdb::FloatGrid::ConstAccessor sun = mLighting.sunInCloudGrid().getConstAccessor();
    openvdb::FloatGrid::ConstAccessor sky = mLighting.skyTransmittanceGrid().getConstAccessor();
    const openvdb::math::Transform& densityTransform = densityGrid.transform();
    const openvdb::math::Transform& lightTransform = mLighting.sunInCloudGrid().transform(); // both grids share it
    // Sunlight travels along -toSun and leaves towards the origin along -dir:
    // the angle between the two is that between dir and toSun.
    const double phase = henyeyGreenstein(dir.dot(mLighting.toSun()), mAnisotropy);
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
    const double voxel = densityGrid.voxelSize()[0];
    if (!intersector.setWorldRay(openvdb::math::Ray<double>(origin, dir, tMin, tMax))) return segment;
    double t0 = 0.0, t1 = 0.0;
    while (segment.transmittance > 0.0 && intersector.march(t0, t1))
        marchInterval(std::max(tMin, t0 * voxel), std::min(tMax, t1 * voxel));
    return segment;
}

} // namespace vfield
