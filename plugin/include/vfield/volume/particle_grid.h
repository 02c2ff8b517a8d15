#pragma once
/// @file particle_grid.h
/// ParticleSet (world space) -> OpenVDB PointDataGrid `particles` with the
/// attributes P, v (world units / s), rest (where the particle was emitted or
/// its rest last reset, Houdini's name for a material coordinate), id (int32)
/// and pscale (radius, world units); with dual rest also rest2, and the
/// grid's float metadata rest2Weight (ParticleSet::rest2Weight).

#include <vfield/sim/particles.h>

#include <openvdb/openvdb.h>

namespace vfield {

/// The grid's voxel size is chosen for about 8 points per voxel. Returned as
/// the base type so that callers need not include OpenVDB's points headers.
openvdb::GridBase::Ptr makeParticleGrid(const ParticleSet& particles);

} // namespace vfield
