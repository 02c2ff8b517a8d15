#pragma once
/// @file mesh_distance.h
/// A mesh's signed distance in its object space (negative inside), held as an
/// OpenVDB level set built with tools::meshToSignedDistanceField: a band of
/// given width outside, and inside as deep as asked (the whole inside, for
/// pushing points out along the gradient). Values are exact at the voxels
/// near the surface and trilinear between them; beyond the outer band they
/// read as its width, a lower bound.

#include <vfield/core/math.h>
#include <vfield/core/trilinear_sampler.h>
#include <vfield/core/vdb_trees.h>
#include <vfield/mesh/triangle_mesh.h>

#include <functional>
#include <vector>

namespace vfield {

class MeshDistance {
public:
    /// Cached reads, one per thread.
    using Accessor = TrilinearSampler<openvdb::FloatTree>;

    /// Told how far the build is, in percent, as OpenVDB's mesh-to-volume
    /// conversion estimates it (a few steps: 30, 45, 50, 54, ..., 99).
    using Progress = std::function<void(int percent)>;

    /// voxelSize, exteriorBand and interiorBand in object units; an interior
    /// band of at least half the mesh's smallest extent fills its whole inside.
    MeshDistance(const TriangleMesh& mesh, double voxelSize, double exteriorBand, double interiorBand,
                 const Progress& progress = {});

    double voxelSize() const { return mVoxelSize; }
    double exteriorBand() const { return mExteriorBand; }
    /// The mesh's bounds grown by the exterior band: where values are meaningful.
    const BBoxd& reach() const { return mReach; }
    Accessor accessor() const { return Accessor(mGrid->tree()); }

    /// Signed distance at an object-space point, trilinear.
    double distance(Accessor& accessor, const Vec3d& p) const;
    /// The distance's gradient (the outward normal near the surface), by
    /// central differences over a voxel; zero where the field is flat.
    Vec3d gradient(Accessor& accessor, const Vec3d& p) const;

private:
    openvdb::FloatGrid::Ptr mGrid;
    double mVoxelSize, mExteriorBand;
    BBoxd mReach;
};

} // namespace vfield
