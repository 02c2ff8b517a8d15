#pragma once
/// @file surface_distance.h
/// Within libvfield's volume stage: the distance to a splat's surface and
/// each voxel's closest point on it, over a band around it (the displaced
/// detail moves that surface).

#include <vfield/core/vdb_trees.h>

namespace vfield {

/// The splat's surface, where its density is surfaceDensity: the signed
/// distance to it (world units, negative inside) and each voxel's closest
/// point on it (index space), over the band of voxels from `inward` inside
/// the surface to `outward` outside it (world units), and the one layer of
/// voxels just beyond it. The density's deeper voxels read -FLT_MAX and
/// have no closest point; nothing farther out is stored.
struct SurfaceDistance {
    openvdb::FloatGrid::Ptr distance;
    openvdb::Vec3SGrid::Ptr closest;

    SurfaceDistance(const openvdb::FloatGrid& density, float surfaceDensity, double inward, double outward);
};

} // namespace vfield
