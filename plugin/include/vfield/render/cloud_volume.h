#pragma once
/// @file cloud_volume.h
/// A frame's density grid (world space) as a participating medium:
/// extinction sigma_t = extinction x density, scattering albedo x sigma_t,
/// Beer-Lambert attenuation, single scattering of the sun with a
/// Henyey-Greenstein phase function, and an isotropic sky term so shadowed
/// cloud is not black.
///
/// The sun's transmittance is computed once per frame into a grid over the
/// cloud's box (through the cloud, and zero where a surface blocks the sun),
/// so a shading sample costs one lookup instead of a march to the sun; the
/// sky's light reaches a sample through the cloud above it, from a second grid.
/// With ImageSettings::skipEmptySpace, rays march only through the OpenVDB
/// nodes that hold density (tools::VolumeRayIntersector).

#include <vfield/render/render_settings.h>
#include <vfield/render/surfaces.h>

#include <openvdb/openvdb.h>

#include <memory>

namespace vfield {

/// Henyey-Greenstein phase function for the cosine between the directions of
/// propagation before and after scattering; integrates to 1 over the sphere.
double henyeyGreenstein(double cosTheta, double g);

class CloudVolume {
public:
    /// occluders may be null (no surface shadows the cloud).
    CloudVolume(openvdb::FloatGrid::ConstPtr density, const ImageSettings& image, const Vec3d& toSun,
                const SurfaceScene* occluders);

    bool empty() const { return mEmpty; }
    const BBoxd& bounds() const { return mBounds; }

    struct Segment {
        Vec3d radiance{0.0};        ///< light scattered towards the ray's origin
        double transmittance = 1.0; ///< of the segment
    };
    /// Integrates origin + t dir (dir unit) for t in [tMin, tMax) in steps of
    /// volumeStep, each sampled at jitter (in [0, 1)) of its length.
    /// sunRadiance and skyRadiance light it.
    Segment march(const Vec3d& origin, const Vec3d& dir, double tMin, double tMax, double jitter, const Vec3d& sunRadiance,
                  const Vec3d& skyRadiance) const;

    /// Transmittance of the cloud from p towards the sun (1 where no cloud is in the way).
    double sunTransmittance(const Vec3d& p) const;

    /// Density x the sky's transmittance down to each voxel: where the cloud
    /// scatters the sky's light, and how much (same voxels as the density).
    openvdb::FloatGrid::Ptr skyLitDensity() const;

    /// Where the ray (dir unit) is inside the cloud's box; false if it misses.
    bool clip(const Vec3d& origin, const Vec3d& dir, double& tMin, double& tMax) const;

private:
    openvdb::FloatGrid::ConstPtr mDensity;
    /// Transmittance towards a light (unit direction) over the box, coarser than the density.
    openvdb::FloatGrid::Ptr transmittanceGrid(const Vec3d& towards, const SurfaceScene* occluders) const;

    openvdb::FloatGrid::Ptr mSunTransmittance, mSkyTransmittance; ///< share one transform
    struct EmptySpaceSkipper;                                     ///< OpenVDB's VolumeRayIntersector, one copy per thread
    std::shared_ptr<EmptySpaceSkipper> mSkipper;                  ///< null: march the whole box
    BBoxd mBounds;
    Vec3d mToSun;
    double mExtinction, mAlbedo, mAnisotropy, mStep;
    bool mEmpty = true;
};

} // namespace vfield
