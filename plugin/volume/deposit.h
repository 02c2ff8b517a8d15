#pragma once
/// @file deposit.h
/// Within libvfield's volume stage: ParticleSet -> the sums a splat blurs.
/// Each particle deposits its trilinear (cloud-in-cell) weights W on the
/// eight voxels around it, times its condensation share, with W v and
/// W rest for each rest channel. The sums are taken in fixed point, of
/// integers, so that they do not depend on the order the particles come in:
/// one run, the merge of its shards and any thread count give the same
/// grids, bit for bit.

#include "fine_grid.h"

#include <vfield/core/vdb_trees.h>
#include <vfield/sim/particles.h>
#include <vfield/volume/volume_detail.h>

#include <vector>

namespace vfield {

struct Deposit {
    openvdb::FloatGrid::Ptr weight;             ///< the sum of W
    openvdb::Vec3SGrid::Ptr momentum;           ///< the sum of W v
    std::vector<openvdb::Vec3SGrid::Ptr> rests; ///< per rest channel, the sum of W rest
};

/// The particles' deposit on a grid of the given transform (a pure scale:
/// index space is world space over the voxel size). Particles in spatial
/// order (ParticleSet::sortSpatially) deposit several times faster than in
/// random order; the result is the same.
Deposit depositParticles(const ParticleSet& particles, const std::vector<RestChannel>& channels,
                         const CondensationSettings& condensation, const openvdb::math::Transform::Ptr& transform);

/// The particles' mean radius, summed in fixed point as the deposit is: the
/// same for the same particles in any order. 1 when there are none.
double meanRadius(const ParticleSet& particles);

} // namespace vfield
