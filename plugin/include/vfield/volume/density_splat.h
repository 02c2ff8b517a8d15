#pragma once
/// @file density_splat.h
/// ParticleSet (world space) -> FloatGrid `density` and Vec3SGrid `vel`
/// (world space, the names Houdini and Blender expect).
///
/// Each particle spreads densityPerParticle over a smooth kernel of radius R,
/// W(r) = 315 / (64 pi R^3) (1 - r^2/R^2)^3, which integrates to 1: the grid's
/// integral is particles x densityPerParticle, and a particle's contribution
/// fades smoothly to zero at R, so nothing pops as particles move. `vel` is
/// the kernel-weighted mean velocity. Sums run in a fixed order whatever the
/// thread count, so grids are identical for any number of threads.

#include <vfield/core/json.h>
#include <vfield/sim/particles.h>

#include <openvdb/openvdb.h>

namespace vfield {

struct VolumeOptions {
    static constexpr double kMaxKernelVoxels = 32.0; ///< the kernel's radius spans at most this many voxels

    double voxelSize = 0.0;          ///< world units (0..1e9); 0: the particles' mean radius
    double kernelRadius = 0.0;       ///< world units (0..1e9); 0: 2 x the particles' mean radius; at least one voxel
    double densityPerParticle = 1.0; ///< density integral of one particle (0..1e12; extinction is density x sigma)

    /// Throws OptionError naming the first option out of range, or a kernel
    /// spanning more than kMaxKernelVoxels voxels.
    void validate() const;
    /// These options with the defaults filled in for particles of the given
    /// mean radius: the only place the defaults are computed. Unchecked: call
    /// validate() on the result.
    VolumeOptions resolved(double meanParticleRadius) const;
};
VolumeOptions volumeOptionsFromJson(const JsonValue& json);

struct DensityGrids {
    openvdb::FloatGrid::Ptr density;
    openvdb::Vec3SGrid::Ptr velocity;
};

/// Splats with options.resolved(mean radius of the particles). Throws
/// OptionError if the voxel size would make an absurd kernel.
DensityGrids splatParticles(const ParticleSet& particles, const VolumeOptions& options);

} // namespace vfield
