#include <vfield/mesh/mesh_distance.h>

#include <openvdb/tools/MeshToVolume.h>

#include <algorithm>
#include <cmath>

namespace vfield {

namespace {

/// OpenVDB's interrupter interface, never interrupting: passes on each new
/// percentage the conversion reports (from the calling thread; its workers
/// ask without one).
class ProgressInterrupter final : public openvdb::util::NullInterrupter {
public:
    explicit ProgressInterrupter(const MeshDistance::Progress& progress) : mProgress(progress) {}
    bool wasInterrupted(int percent = -1) override
    {
        if (percent >= 0 && percent != mLastPercent && mProgress) mProgress(mLastPercent = percent);
        return false;
    }

private:
    const MeshDistance::Progress& mProgress;
    int mLastPercent = -1;
};

} // namespace

MeshDistance::MeshDistance(const TriangleMesh& mesh, double voxelSize, double exteriorBand, double interiorBand,
                           const Progress& progress)
    : mVoxelSize(voxelSize), mExteriorBand(exteriorBand)
{
    const auto transform = openvdb::math::Transform::createLinearTransform(voxelSize);
    const std::vector<openvdb::Vec3I> triangles(mesh.triangles.begin(), mesh.triangles.end());
    // Bands are in voxels; at least the three a trilinear lookup and a central difference need.
    const float exterior = float(std::max(3.0, std::ceil(exteriorBand / voxelSize)));
    const float interior = float(std::max(3.0, std::ceil(interiorBand / voxelSize)));
    ProgressInterrupter progressInterrupter(progress);
    // By the base's reference: libopenvdb's own instantiation for
    // NullInterrupter is used (virtual calls reach ours), where our type
    // would instantiate the whole conversion here again.
    openvdb::util::NullInterrupter& interrupter = progressInterrupter;
    mGrid = openvdb::tools::meshToSignedDistanceField<openvdb::FloatGrid>(interrupter, *transform, mesh.points, triangles, {},
                                                                          exterior, interior);
    mExteriorBand = exterior * voxelSize;
    mReach = mesh.bounds();
    mReach.expand(mExteriorBand);
}

double MeshDistance::distance(Accessor& accessor, const Vec3d& p) const { return accessor.atIndex(p / mVoxelSize); }

Vec3d MeshDistance::gradient(Accessor& accessor, const Vec3d& p) const
{
    Vec3d g;
    for (int axis = 0; axis < 3; ++axis) {
        Vec3d step(0.0);
        step[axis] = 0.5 * mVoxelSize;
        g[axis] = (distance(accessor, p + step) - distance(accessor, p - step)) / mVoxelSize;
    }
    return g;
}

} // namespace vfield
