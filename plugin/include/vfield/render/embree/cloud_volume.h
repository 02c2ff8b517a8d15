#pragma once
/// @file cloud_volume.h
/// A frame's lit cloud (CloudLighting) as a participating medium for vfield's
/// own renderer: extinction sigma_t = extinction x density, scattering
/// albedo x sigma_t, Beer-Lambert attenuation, the sun scattered with the
/// medium's two-lobe phase function and the sky's light reaching each sample
/// through the cloud above it, both in octaves of multiple scattering
/// (MultipleScattering): light scattered many times brightens the cloud's
/// shadowed side and softens its shadow on the ground.
/// With IntegratorSettings::skipEmptySpace, rays march only through the
/// OpenVDB nodes that hold density (tools::VolumeRayIntersector).

#include <vfield/render/cloud_lighting.h>

#include <memory>
#include <vector>

namespace vfield {

class CloudVolume {
public:
    /// lighting must outlive the volume.
    CloudVolume(const CloudLighting& lighting, const MediumSettings& medium, const IntegratorSettings& integrator);

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
    /// sunRadiance and skyRadiance light it.
    Segment march(const Vec3d& origin, const Vec3d& dir, double tMin, double tMax, double jitter, const Vec3d& sunRadiance,
                  const Vec3d& skyRadiance) const;

private:
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
    /// The steps of the march towards a light through the density, before its grid is read.
    std::vector<double> mNearSteps;
};

} // namespace vfield
