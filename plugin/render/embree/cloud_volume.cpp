#include <vfield/render/embree/cloud_volume.h>

#include <vfield/core/trilinear_sampler.h>

#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/RayIntersector.h>

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

namespace vfield {

namespace {
/// The march towards each light: this many steps of a density voxel, then the light's OpticalDepthMap.
constexpr int kNearSteps = 4;
/// Optical depth beyond which no light is left to reach a sample (e^-7 < 0.001).
constexpr double kOpaqueDepth = 7.0;
const Vec3d kUp(0.0, 1.0, 0.0); ///< towards the sky, as CloudLighting's sky grid
} // namespace

/// Where the density's trilinear reads can be non-zero: its voxels above
/// zero, dilated by one across faces, edges and corners, so that a read whose
/// cell's first corner is outside reads eight zeros. OpenVDB's intersector
/// dilates across faces only, and would skip the leaves diagonally behind a
/// leaf's corner, whose cells read that corner. The ray march also tests it
/// before each read: where a cloud has wisps, most steps fall on empty
/// voxels of the leaves that hold them.
struct CloudVolume::EmptySpaceSkipper {
    using Intersector = openvdb::tools::VolumeRayIntersector<openvdb::MaskGrid>;
    explicit EmptySpaceSkipper(openvdb::MaskGrid::Ptr occupancy)
        : occupied(std::move(occupancy)), master(*occupied), perThread(master)
    {}
    /// Dilated by `reach` more (world units): where reads displaced by a CloudMotion can be non-zero.
    static openvdb::MaskGrid::Ptr occupancy(const openvdb::FloatGrid& density, double reach)
    {
        openvdb::MaskGrid::Ptr mask = openvdb::MaskGrid::create();
        mask->setTransform(density.transform().copy());
        mask->tree().topologyUnion(density.tree());
        openvdb::tree::ValueAccessor<openvdb::MaskTree> accessor(mask->tree());
        for (auto leaf = density.tree().cbeginLeaf(); leaf; ++leaf)
            for (auto voxel = leaf->cbeginValueOn(); voxel; ++voxel)
                if (*voxel <= 0.0f) accessor.setValueOff(voxel.getCoord());
        const int voxels = 1 + int(std::ceil(reach / density.voxelSize()[0]));
        openvdb::tools::dilateActiveValues(mask->tree(), voxels, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                           openvdb::tools::EXPAND_TILES);
        mask->tree().prune();
        return mask;
    }
    openvdb::MaskGrid::Ptr occupied;
    Intersector master;                                     ///< over occupied's nodes
    tbb::enumerable_thread_specific<Intersector> perThread; ///< copies share the master's tree
};

CloudVolume::CloudVolume(const CloudLighting& lighting, const MediumSettings& medium, const IntegratorSettings& integrator,
                         double motionReach)
    : mLighting(lighting), mExtinction(medium.extinction), mAlbedo(medium.albedo), mStep(integrator.volumeStep),
      mMotionReach(motionReach)
{
    const MultipleScatteringSettings& ms = integrator.multipleScattering;
    for (int i = 0; i < ms.octaves; ++i) {
        Octave octave{std::pow(ms.scatteringFalloff, i), std::pow(ms.extinctionFalloff, i), std::pow(ms.skyScatteringFalloff, i),
                      medium};
        octave.medium.anisotropy *= std::pow(ms.eccentricityFalloff, i);
        octave.medium.backAnisotropy *= std::pow(ms.eccentricityFalloff, i);
        mOctaves.push_back(octave);
    }
    if (!lighting.empty() && integrator.skipEmptySpace) {
        // A density with no voxel above zero (OpenVDB's intersector refuses
        // an empty grid) is marched across its box, reading zeros.
        openvdb::MaskGrid::Ptr occupied = EmptySpaceSkipper::occupancy(lighting.density(), motionReach);
        if (!occupied->empty()) mSkipper = std::make_shared<EmptySpaceSkipper>(std::move(occupied));
    }
    if (lighting.empty()) return;
    mNearStep = lighting.density().voxelSize()[0];
    mSunDepth = OpticalDepthMap(lighting.densityPtr(), lighting.toSun());
    // The sky's map serves the octaves alone, and takes time to make: with
    // paths, the sky's light is what the paths that escape to it bring.
    if (ms.method == MultipleScatteringMethod::Octaves) mSkyDepth = OpticalDepthMap(lighting.densityPtr(), kUp);
}

double CloudVolume::surfaceSunTransmittance(const Vec3d& p) const
{
    const double transmittance = mLighting.sunTransmittance(p);
    if (transmittance >= 1.0) return 1.0;
    // The octaves' transmittances T^(b^i), averaged with weights a^i b^i (an
    // octave that sees b^i of the extinction scatters b^i as much towards the
    // ground): 1 without a cloud and never more. Under spheres of cloud of
    // optical radius 0.9 to 9 this is the reference's shadow within 8%; with
    // weights a^i it is too bright, and the octaves' sum that lights the cloud
    // from inside, T + a^i (T^(b^i) - T), exceeds the sun's light under a thin cloud.
    double sum = 0.0, weights = 0.0;
    for (const Octave& octave : mOctaves) {
        const double weight = octave.scattering * octave.extinction;
        sum += weight * std::pow(transmittance, octave.extinction);
        weights += weight;
    }
    return sum / weights;
}

CloudVolume::OctavePhases CloudVolume::octavePhases(const Vec3d& dir) const
{
    OctavePhases phases{};
    for (std::size_t i = 0; i < mOctaves.size(); ++i) phases[i] = mOctaves[i].medium.phase(dir.dot(mLighting.toSun()));
    return phases;
}

float CloudVolume::transmittance(double depth) const
{
    const double opticalDepth = mExtinction * depth;
    return opticalDepth > kOpaqueDepth ? 0.0f : float(std::exp(-opticalDepth));
}

// The first voxels of p's own way towards the light are marched: the map's
// columns, a voxel apart, blur a dense lump's lit edge across the rays, so a
// sample just inside a lump would take depth from beside it. Read from p on,
// a sphere of dense lumps a voxel or two across comes out darker than the
// reference lit from behind the camera; with four voxels marched, it matches
// (tests/render/reference_integrator_test.cpp). Farther on, the blur draws depth
// from lumps all around, and evens out.
double CloudVolume::depthTowards(LightReaders& light, OpticalDepthMap::Reader& beyond, const Vec3d& p, const Vec3d& towards) const
{
    const openvdb::math::Transform& transform = mLighting.density().transform();
    double depth = 0.0, s = 0.0;
    for (int i = 0; i < kNearSteps; ++i, s += mNearStep)
        depth += light.near.atIndex(transform.worldToIndex(p + towards * (s + 0.5 * mNearStep))) * mNearStep;
    return depth + beyond.at(p + towards * s);
}

float CloudVolume::sunThroughCloud(LightReaders& light, const Vec3d& p) const
{
    return transmittance(depthTowards(light, light.sun, p, mLighting.toSun()));
}

float CloudVolume::sunThrough(LightReaders& light, const Vec3d& p) const
{
    return mLighting.sunVisible(p) * sunThroughCloud(light, p);
}

CloudVolume::OctaveLight CloudVolume::octaveLight(LightReaders& readers, const Vec3d& p, const OctavePhases& phases) const
{
    const float sunT = sunThrough(readers, p), skyT = transmittance(depthTowards(readers, readers.sky, p, kUp));
    // The sky lights the cloud through the cloud above it, so bases darken
    // and tops stay bright. Octave 0 is single scattering, the light seen
    // through T; octave i >= 1 adds a^i of the light the cloud took away,
    // T^(b^i) - T (e^(b^i ln T) - T): nothing where the cloud is thin, more
    // deep inside. The sky's light, diffuse already, takes its own a. A light
    // blocked outright (T = 0: a surface in the way) stays dark in every octave.
    const double logSun = std::log(std::min(double(sunT), 1.0)), logSky = std::log(std::min(double(skyT), 1.0));
    OctaveLight light;
    light.sunShare = phases[0] * sunT;
    light.skyShare = skyT;
    for (std::size_t i = 1; i < mOctaves.size(); ++i) {
        const Octave& octave = mOctaves[i];
        if (sunT > 0.0f) light.sunShare += octave.scattering * phases[i] * (std::exp(octave.extinction * logSun) - sunT);
        if (skyT > 0.0f) light.skyShare += octave.skyScattering * (std::exp(octave.extinction * logSky) - skyT);
    }
    return light;
}

CloudVolume::Segment CloudVolume::march(const Vec3d& origin, const Vec3d& dir, double tMin, double tMax, double jitter,
                                        const Vec3d& sunRadiance, const Vec3d& skyRadiance, const ScatteredLightGrid* scattered,
                                        CloudMotion::Instant* motion) const
{
    Segment segment;
    const double start = tMin; // the steps are counted from here, not from the box (below)
    if (!mLighting.clip(origin, dir, tMin, tMax, mMotionReach)) return segment;
    const openvdb::FloatGrid& densityGrid = mLighting.density();
    Density density(densityGrid.tree());
    LightReaders light(*this);
    const openvdb::math::Transform& densityTransform = densityGrid.transform();
    // Sunlight travels along -toSun and leaves towards the origin along -dir:
    // the angle between the two is that between dir and toSun.
    const OctavePhases phases = octavePhases(dir);

    double opacitySum = 0.0, weightedDistance = 0.0;
    const auto finished = [&] {
        if (opacitySum > 0.0) segment.distance = weightedDistance / opacitySum;
        return segment;
    };
    // Stratified: step k covers [start + k step, start + (k + 1) step), the
    // last cut at tMax, and samples it at a jittered point; a step that
    // begins before the cloud's box samples nothing there. The steps are
    // counted from the ray's start, not from where it enters the box: the box
    // changes with the cloud, and steps counted from its face sampled other
    // points of every ray in every frame, which boiled in a shot where the
    // cloud barely moves. So across the empty-space skipper's spans too:
    // restarted at each span, they sampled other depths on either side of a
    // span's start, which showed as stripes along the tree's node boundaries.
    double nextStep = 0.0; // the first step not yet marched
    using Occupied = openvdb::tree::ValueAccessor<const openvdb::MaskTree, /*IsSafe=*/false>;
    std::optional<Occupied> occupied;
    if (mSkipper) occupied.emplace(mSkipper->occupied->tree());
    const auto marchInterval = [&](double from, double to) {
        for (double k = std::max(nextStep, std::floor((from - start) / mStep)); segment.transmittance > 0.0; k += 1.0) {
            const double t = start + k * mStep;
            if (t >= to) break;
            nextStep = k + 1.0;
            const double dt = std::min(mStep, tMax - t);
            const Vec3d onRay = origin + dir * (t + jitter * dt);
            const Vec3d p = motion ? motion->source(onRay) : onRay;
            const Vec3d index = densityTransform.worldToIndex(p);
            if (occupied && !occupied->isValueOn(openvdb::Coord::floor(index))) continue;
            const double rho = density.atIndex(index);
            if (rho <= 0.0) continue;
            const double stepTransmittance = std::exp(-mExtinction * rho * dt);
            const double opacity = segment.transmittance * (1.0 - stepTransmittance);
            // In-scattered light of the step, integrated exactly for constant density:
            // (1 - e^(-sigma_t dt)) * albedo * source.
            Vec3d source;
            if (scattered) { // the sun's single scattering, and the rest as the paths found it
                source = sunRadiance * (phases[0] * sunThrough(light, p)) + scattered->at(p);
            } else {
                const OctaveLight octaves = octaveLight(light, p, phases);
                source = sunRadiance * octaves.sunShare + skyRadiance * octaves.skyShare;
            }
            segment.radiance += opacity * mAlbedo * source;
            opacitySum += opacity;
            weightedDistance += opacity * (t + jitter * dt);
            segment.transmittance *= stepTransmittance;
            if (segment.transmittance < 1e-3) segment.transmittance = 0.0;
        }
    };
    if (!mSkipper) {
        marchInterval(tMin, tMax);
        return finished();
    }
    // Only the spans of leaves that hold density; index-space times scale by the voxel size.
    EmptySpaceSkipper::Intersector& intersector = mSkipper->perThread.local();
    const double voxel = densityGrid.voxelSize()[0];
    if (!intersector.setWorldRay(openvdb::math::Ray<double>(origin, dir, tMin, tMax))) return finished();
    double t0 = 0.0, t1 = 0.0;
    while (segment.transmittance > 0.0 && intersector.march(t0, t1))
        marchInterval(std::max(tMin, t0 * voxel), std::min(tMax, t1 * voxel));
    return finished();
}

} // namespace vfield
