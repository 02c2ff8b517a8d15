#pragma once
/// @file optical_depth_map.h
/// How much cloud lies between each point and a distant light: the density's
/// integral from the point towards the light, out to the cloud's edge, on a
/// lattice aligned with the light's rays, as fine as the density (a voxel
/// apart across the rays and along them), computed once per frame and stored
/// (an OpenVDB tree) only over the density and the empty stretches between
/// its parts along the light. Each column of the lattice accumulates along
/// itself (trapezoids between its points).
///
/// Why not a march per sample, or a coarse grid: the transmittance is the
/// exponential of the depth, so an error that varies from sample to sample
/// brightens the cloud on average (Jensen's inequality), and a coarse grid,
/// whose cells average the density across several rays, darkens it: marched
/// per sample near the point and then read from a coarse grid, a displaced
/// cumulus's single scattering strays several percent from the reference
/// path tracer's, one way or the other; marched in half-voxel steps through
/// the whole cloud for every sample, or read from this map once a frame, it
/// is the reference's within about 1% (docs/rendering.md, "Accuracy").

#include <vfield/core/math.h>
#include <vfield/core/trilinear_sampler.h>
#include <vfield/core/vdb_trees.h>

namespace vfield {

class OpticalDepthMap {
public:
    OpticalDepthMap() = default;
    /// towardsLight: unit, from the cloud towards the light. The lattice's
    /// spacing is the density's voxel size, along and across the rays.
    OpticalDepthMap(openvdb::FloatGrid::ConstPtr density, const Vec3d& towardsLight);

    /// Reads the map, for one thread (it keeps the leaves it last read).
    class Reader {
    public:
        explicit Reader(const OpticalDepthMap& map) : mMap(&map), mDepthAt(*map.mDepth), mDensityAt(map.mDensity->tree()) {}
        /// The integral of the density from p towards the light, world units
        /// x density, 0 where the map holds nothing (no density between p and
        /// the light): p's own way to the lattice's next slice towards the
        /// light (the density read halfway), then that slice's four columns
        /// around it, bilinearly. Where some of those have met cloud and some
        /// not, at the cloud's lit edge, p's own way goes on a slice at a
        /// time (at most eight) until all or none have. The depth bends there
        /// from none to growing fast, and read across the bend (or along it,
        /// trilinearly between slices) it comes out too deep just inside the
        /// edge, and a sphere of cloud (tests/render/optical_depth_map_test.cpp)
        /// lets through several percent too little light; p's own way keeps
        /// that within 1 to 2%.
        double at(const Vec3d& p);

    private:
        const OpticalDepthMap* mMap;
        TrilinearSampler<openvdb::FloatTree> mDepthAt, mDensityAt; ///< mDepthAt reads single points (valueAt)
    };

private:
    /// The lattice coordinates of a world point: along the two axes across
    /// the rays and along the light's travel.
    Vec3d indexOf(const Vec3d& p) const { return Vec3d(p.dot(mAcross1), p.dot(mAcross2), p.dot(mAlong)) * mInverseSpacing; }

    Vec3d mAcross1{1, 0, 0}, mAcross2{0, 0, 1}, mAlong{0, -1, 0}; ///< mAlong: the light's travel, away from it
    double mInverseSpacing = 1.0;
    openvdb::FloatGrid::ConstPtr mDensity = openvdb::FloatGrid::create();
    openvdb::FloatTree::Ptr mDepth = std::make_shared<openvdb::FloatTree>(0.0f); ///< lattice coordinates
};

} // namespace vfield
