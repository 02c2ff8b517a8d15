#pragma once
/// @file field_grid.h
/// OctreeField (object space) -> OpenVDB grids (world space through the
/// object's transform): `force` (Vec3SGrid, direction x magnitude), and for
/// inspection `level` (Int32Grid) and `surface` (BoolGrid).
///
/// With the default voxel size (the finest leaf's side) voxel centres sit at
/// the centres of the finest cells, so a nearest-voxel lookup anywhere inside
/// the root returns exactly the octree's answer. Leaves larger than an OpenVDB
/// node become tiles, so memory follows the octree, not the dense cube.

#include <vfield/core/math.h>
#include <vfield/core/vdb_trees.h>
#include <vfield/field/octree_field.h>

#include <optional>

namespace vfield {

struct VoxelizeOptions {
    /// Voxel edge, object-space units. Unset: the finest leaf's side.
    std::optional<double> voxelSize;
    /// Places the field in the world: the grids' transform is
    /// worldFromObject applied after the object-space voxel transform.
    Mat4d worldFromObject = Mat4d::identity();
    bool withLevel = true;   ///< also make the `level` grid
    bool withSurface = true; ///< also make the `surface` grid
};

struct FieldGrids {
    openvdb::Vec3SGrid::Ptr force;
    openvdb::Int32Grid::Ptr level;   ///< null unless asked for
    openvdb::BoolGrid::Ptr surface;  ///< null unless asked for; active (true) in surface leaves only
    openvdb::GridPtrVec all() const; ///< the grids that exist, for writing
};

/// Voxelizes every leaf of the field; each voxel whose centre lies in a leaf
/// takes that leaf's values. The whole root is active; outside it the
/// background (zero) applies.
FieldGrids voxelizeField(const OctreeField& field, const VoxelizeOptions& options = {});

/// The deepest level the smooth force grid is made at: 256^3 voxels (200 MB)
/// at most. Cells of this level cut finer take the average of their leaves.
constexpr int kSmoothForceMaxLevel = 9;

/// The field made continuous (FieldSampling::Dual), object space: a force
/// per cell centre of level min(depth, kSmoothForceMaxLevel), to be read
/// trilinearly. Built coarse to fine: a level's lattice of cell centres
/// holds each node's own force where a node of that level lies (a leaf's, or
/// an interior node's unboosted average normal), and elsewhere, inside a
/// coarser leaf, the coarser lattices' trilinear interpolant. So between
/// leaves of one level the force changes linearly from centre to centre, and
/// where the level changes it turns from the coarse leaf's force to the
/// finer ones' over half the coarse leaf's width instead of stepping at the
/// face; a surface leaf's boost reaches at most one of its widths beyond it.
/// Every voxel of the root is active (memory: the dense lattice).
openvdb::Vec3SGrid::Ptr smoothForceGrid(const OctreeField& field);

} // namespace vfield
