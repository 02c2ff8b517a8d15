#pragma once
/// @file cloud_volume.h
/// A frame's lit cloud (CloudLighting) as a participating medium for vfield's
/// own renderer: extinction sigma_t = extinction x density, scattering
/// albedo x sigma_t, Beer-Lambert attenuation, single scattering of the sun
/// with a Henyey-Greenstein phase function, and the sky's light reaching each
/// sample through the cloud above it (so shadowed cloud is not black).
/// With IntegratorSettings::skipEmptySpace, rays march only through the
/// OpenVDB nodes that hold density (tools::VolumeRayIntersector).

#include <vfield/render/cloud_lighting.h>

#include <memory>

namespace vfield {

/// Henyey-Greenstein phase function for the cosine between the directions of
/// propagation before and after scattering; integrates to 1 over the sphere.
double henyeyGreenstein(double cosTheta, double g);

class CloudVolume {
public:
    /// lighting must outlive the volume.
    CloudVolume(const CloudLighting& lighting, const MediumSettings& medium, const IntegratorSettings& integrator);

    bool empty() const { return mLighting.empty(); }
    const CloudLighting& lighting() const { return mLighting; }

    struct Segment {
        Vec3d radiance{0.0};        ///< light scattered towards the ray's origin
        double transmittance = 1.0; ///< of the segment
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
    double mExtinction, mAlbedo, mAnisotropy, mStep;
};

} // namespace vfield
