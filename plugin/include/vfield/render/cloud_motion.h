#pragma once
/// @file cloud_motion.h
/// A frame's cloud over an open shutter, as Cycles and Karma blur a volume by
/// its velocity grid: what lies at p, `seconds` after the frame's instant, is
/// what the frame's density (and the light in it) holds at p - vel(p) seconds.
///
/// The simulation's `vel` grid covers the density's voxels only, so a read
/// just ahead of a moving cloud would find no velocity and the cloud would
/// be smeared back but never carried forward. The grid is therefore
/// extended outward, a ring of voxels at a time, each new voxel the mean of
/// its neighbours', until it reaches as far as its fastest voxel moves over
/// the shutter.

#include <vfield/core/math.h>
#include <vfield/core/trilinear_sampler.h>
#include <vfield/core/vdb_trees.h>

namespace vfield {

class CloudMotion {
public:
    /// velocity in world units a second; longestSeconds: how far from the
    /// frame's instant the shutter reaches, either way.
    CloudMotion(const openvdb::Vec3SGrid& velocity, double longestSeconds);

    /// The farthest any read is displaced: the fastest voxel's speed times longestSeconds.
    double reach() const { return mReach; }
    const openvdb::Vec3SGrid& velocity() const { return *mVelocity; }

    /// The displacement at one instant, read by one thread.
    class Instant {
    public:
        Instant(const CloudMotion& motion, double seconds)
            : mVelocity(motion.mVelocity->tree()), mTransform(&motion.mVelocity->transform()), mSeconds(seconds)
        {}
        /// Where the frame's cloud holds what lies at p at this instant.
        Vec3d source(const Vec3d& p)
        {
            if (mSeconds == 0.0) return p;
            return p - velocity(p) * mSeconds;
        }
        /// The cloud's velocity at p (world units a second), read trilinearly.
        Vec3d velocity(const Vec3d& p) { return Vec3d(mVelocity.atIndex(mTransform->worldToIndex(p))); }

    private:
        TrilinearSampler<openvdb::Vec3STree> mVelocity;
        const openvdb::math::Transform* mTransform;
        double mSeconds;
    };

private:
    openvdb::Vec3SGrid::Ptr mVelocity; ///< extended
    double mReach = 0.0;
};

} // namespace vfield
