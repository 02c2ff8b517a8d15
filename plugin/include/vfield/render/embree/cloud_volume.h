#pragma once
/// @file cloud_volume.h
/// A frame's lit cloud (CloudLighting) as a participating medium for vfield's
/// own renderer: extinction sigma_t = extinction x density, scattering
/// albedo x sigma_t, Beer-Lambert attenuation, the sun scattered with the
/// medium's two-lobe phase function and the sky's light reaching each sample
/// through the cloud above it (the way to each marched near the sample, then
/// read from an OpticalDepthMap), both in octaves of multiple scattering
/// (MultipleScatteringSettings): light scattered many times brightens the cloud's
/// shadowed side and softens its shadow on the ground. Or, for the light
/// scattered more than once, a frame's lattice traced by the reference's
/// paths (ScatteredLightGrid).
/// With IntegratorSettings::skipEmptySpace, rays march only through the
/// OpenVDB leaves where a trilinear read of the density can be above zero
/// (tools::VolumeRayIntersector), and read it only at such voxels.

#include <vfield/core/trilinear_sampler.h>
#include <vfield/render/cloud_lighting.h>
#include <vfield/render/cloud_motion.h>
#include <vfield/render/optical_depth_map.h>

#include <array>
#include <memory>
#include <vector>

namespace vfield {

/// The light that leaves points of a lattice over the cloud after they
/// scatter it: what a path that scatters near a point carries back from the
/// rest of its way (the point's own albedo and the sun's direct light there
/// left out), in RGB, read trilinearly. Gathered per frame from the
/// reference's camera paths (path_tracer.h), read by the fast integrator's march.
struct ScatteredLightGrid {
    std::array<DenseGrid, 3> rgb;
    Vec3d at(const Vec3d& p) const { return Vec3d(rgb[0].at(p), rgb[1].at(p), rgb[2].at(p)); }
};

class CloudVolume {
public:
    /// lighting must outlive the volume. motionReach: the farthest a
    /// CloudMotion displaces a read (0 without motion blur); the march then
    /// looks that much beyond the density's voxels.
    CloudVolume(const CloudLighting& lighting, const MediumSettings& medium, const IntegratorSettings& integrator,
                double motionReach = 0.0);

    bool empty() const { return mLighting.empty(); }
    /// The share of the sun that reaches a surface point through the cloud:
    /// the octaves' transmittances weighted as their scattering, so that light
    /// scattered forward through a thin cloud softens its shadow.
    double surfaceSunTransmittance(const Vec3d& p) const;
    const CloudLighting& lighting() const { return mLighting; }

    struct Segment {
        Vec3d radiance{0.0};        ///< light scattered towards the ray's origin
        double transmittance = 1.0; ///< of the segment
        /// Where along the ray the cloud's light comes from: the
        /// transmittance-weighted mean distance of its scattering (for haze).
        double distance = 0.0;
    };
    /// Integrates origin + t dir (dir unit) for t in [tMin, tMax) in steps of
    /// volumeStep, each sampled at jitter (in [0, 1)) of its length.
    /// sunRadiance and skyRadiance light it, and the octaves give back what
    /// the cloud scatters more than once; with `scattered`, only the sun's
    /// single scattering is marched and the rest of the light read from it.
    /// With `motion`, each sample reads the cloud where the motion brought it from.
    Segment march(const Vec3d& origin, const Vec3d& dir, double tMin, double tMax, double jitter, const Vec3d& sunRadiance,
                  const Vec3d& skyRadiance, const ScatteredLightGrid* scattered = nullptr,
                  CloudMotion::Instant* motion = nullptr) const;

    /// A reader of the density, for one thread.
    using Density = TrilinearSampler<openvdb::FloatTree>;
    /// What a sample reads on its way towards the lights, for one thread:
    /// the density near it and the optical depth maps beyond.
    struct LightReaders {
        explicit LightReaders(const CloudVolume& volume)
            : near(volume.mLighting.density().tree()), sun(volume.mSunDepth), sky(volume.mSkyDepth)
        {}
        Density near;
        OpticalDepthMap::Reader sun, sky;
    };
    /// The sun's transmittance through the cloud from p, as the march takes
    /// it for single scattering. Surfaces in the way are not counted.
    float sunThroughCloud(LightReaders& light, const Vec3d& p) const;
    /// The sun's share that reaches a point of the cloud, as the march's
    /// samples take it: through the cloud, and where a surface blocks it as
    /// CloudLighting's coarse grid has it (not for points on a surface,
    /// whose grid points below it are in the surface's own shadow).
    float sunThrough(LightReaders& light, const Vec3d& p) const;

private:
    using OctavePhases = std::array<double, 8>; ///< MultipleScatteringSettings::octaves is at most 8
    /// The phase of each octave for light leaving along -dir.
    OctavePhases octavePhases(const Vec3d& dir) const;
    /// A light's transmittance through `depth` (OpticalDepthMap's units): 0 once under 0.001.
    float transmittance(double depth) const;
    /// The density's integral from p towards a light (unit direction):
    /// marched near p, read from the light's map beyond.
    double depthTowards(LightReaders& light, OpticalDepthMap::Reader& beyond, const Vec3d& p, const Vec3d& towards) const;
    /// A sample's light as the octaves give it, in units of the sun's and the sky's radiance.
    struct OctaveLight {
        double sunShare = 0.0; ///< all octaves of the sun, single scattering included, their phases applied
        double skyShare = 0.0; ///< the sky's
    };
    OctaveLight octaveLight(LightReaders& readers, const Vec3d& p, const OctavePhases& phases) const;

    const CloudLighting& mLighting;
    struct EmptySpaceSkipper;                    ///< OpenVDB's VolumeRayIntersector, one copy per thread
    std::shared_ptr<EmptySpaceSkipper> mSkipper; ///< null: march the whole box
    /// Per octave of multiple scattering: its share of the light (a^i) and of the extinction (b^i).
    struct Octave {
        double scattering, extinction;
        double skyScattering;  ///< a_sky^i
        MediumSettings medium; ///< with the phase's eccentricity scaled by c^i
    };
    std::vector<Octave> mOctaves;
    double mExtinction, mAlbedo, mStep;
    double mMotionReach; ///< CloudMotion::reach(), 0 without motion blur
    /// The density's integral towards the sun and up to the sky.
    OpticalDepthMap mSunDepth, mSkyDepth;
    double mNearStep = 0.0; ///< the march's steps towards a light before its map is read: a density voxel
};

} // namespace vfield
