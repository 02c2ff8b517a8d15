#include <vfield/render/cloud_motion.h>

#include <openvdb/tools/Morphology.h>
#include <openvdb/tree/LeafManager.h>

#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>

namespace vfield {

namespace {

float fastestSpeed(const openvdb::Vec3SGrid& velocity)
{
    openvdb::tree::LeafManager<const openvdb::Vec3STree> leaves(velocity.tree());
    return tbb::parallel_reduce(
        leaves.leafRange(), 0.0f,
        [](const auto& range, float fastest) {
            for (auto leaf = range.begin(); leaf; ++leaf)
                for (auto v = leaf->cbeginValueOn(); v; ++v) fastest = std::max(fastest, v->length());
            return fastest;
        },
        [](float a, float b) { return std::max(a, b); });
}

/// One ring of voxels around the active ones, each the mean of its active
/// neighbours (across faces, edges and corners) before the ring was added.
void extendByOneVoxel(openvdb::Vec3SGrid& velocity)
{
    const openvdb::Vec3SGrid::Ptr before = velocity.deepCopy();
    openvdb::tools::dilateActiveValues(velocity.tree(), 1, openvdb::tools::NN_FACE_EDGE_VERTEX, openvdb::tools::EXPAND_TILES);
    openvdb::tree::LeafManager<openvdb::Vec3STree> leaves(velocity.tree());
    leaves.foreach ([&](openvdb::Vec3STree::LeafNodeType& leaf, std::size_t) {
        openvdb::tree::ValueAccessor<const openvdb::Vec3STree, false> old(before->tree());
        for (auto v = leaf.beginValueOn(); v; ++v) {
            const openvdb::Coord ijk = v.getCoord();
            if (old.isValueOn(ijk)) continue;
            openvdb::Vec3s sum(0.0f);
            int count = 0;
            for (int dx = -1; dx <= 1; ++dx)
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dz = -1; dz <= 1; ++dz) {
                        openvdb::Vec3s value;
                        if (old.probeValue(ijk.offsetBy(dx, dy, dz), value)) {
                            sum += value;
                            ++count;
                        }
                    }
            v.setValue(count > 0 ? sum / float(count) : openvdb::Vec3s(0.0f));
        }
    });
}

} // namespace

CloudMotion::CloudMotion(const openvdb::Vec3SGrid& velocity, double longestSeconds) : mVelocity(velocity.deepCopy())
{
    mReach = double(fastestSpeed(velocity)) * std::abs(longestSeconds);
    // The reach in voxels, and one more: a trilinear read reaches a voxel past its point.
    const int rings = mReach > 0.0 ? int(std::ceil(mReach / velocity.voxelSize()[0])) + 1 : 0;
    for (int ring = 0; ring < rings; ++ring) extendByOneVoxel(*mVelocity);
}

} // namespace vfield
