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
    double voxelSize = 0.0;          ///< world units; 0: the mean particle radius
    double kernelRadius = 0.0;       ///< world units; 0: 2 x the mean particle radius (>= voxel size)
    double densityPerParticle = 1.0; ///< density integral of one particle (extinction is density x sigma)
};
VolumeOptions volumeOptionsFromJson(const JsonValue& json);

struct DensityGrids {
    openvdb::FloatGrid::Ptr density;
    openvdb::Vec3SGrid::Ptr velocity;
};

/// Throws ValueError if the voxel size would make an absurd grid.
DensityGrids splatParticles(const ParticleSet& particles, const VolumeOptions& options);

} // namespace vfield
