#pragma once
/// @file particle_grid.h
/// ParticleSet (world space) -> OpenVDB PointDataGrid `particles` with the
/// attributes P, v (world units / s), rest (where the particle was emitted or
/// its rest last reset, Houdini's name for a material coordinate), id (int32)
/// and pscale (radius, world units); with dual rest also rest2, and the
/// grid's float metadata rest2Weight (ParticleSet::rest2Weight).

#include <vfield/core/fields.h>
#include <vfield/core/vdb_trees.h>
#include <vfield/sim/particles.h>

namespace vfield {

/// How the particles' attributes are stored, the way OpenVDB's point codecs do.
enum class ParticlePrecision {
    /// P in 16 bits within its voxel (FixedPointCodec: a 65536th of a voxel),
    /// v, rest and rest2 as 16-bit floats (TruncateCodec: 1 part in 2048),
    /// pscale in 8 bits (a 255th of a unit) when every radius is at most 1,
    /// else as a 16-bit float, and one value per leaf where its points share
    /// it; id as is.
    Compact,
    Full ///< every attribute as 32-bit floats
};
inline constexpr EnumName<ParticlePrecision> kParticlePrecisionNames[] = {{ParticlePrecision::Compact, "compact"},
                                                                          {ParticlePrecision::Full, "full"}};
constexpr const auto& enumNames(ParticlePrecision) { return kParticlePrecisionNames; }

/// The grid's voxel size is chosen for about 16 points per voxel. Returned as
/// the base type so that callers need not include OpenVDB's points headers.
/// withState also writes `peak` and `origin` (float) and `cloud` (int32), the rest of what
/// the simulator keeps per particle, and `worldP`, each position exactly as
/// the simulator holds it: what a shard of a sharded simulation hands to its
/// merge (readParticleGrid), which then splats the positions one run splats.
openvdb::GridBase::Ptr makeParticleGrid(const ParticleSet& particles, ParticlePrecision precision = ParticlePrecision::Full,
                                        bool withState = false);

/// The particles of a grid makeParticleGrid made, in id order: every
/// attribute it holds (peak, origin and cloud only from one made withState; else
/// they stay empty). Positions come back exactly from one made withState,
/// else within a millionth of a voxel.
/// Throws ValueError when it is not such a grid.
ParticleSet readParticleGrid(const openvdb::GridBase& grid);

} // namespace vfield
