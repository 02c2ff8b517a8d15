#pragma once
/// @file trilinear_sampler.h
/// Trilinear reads of an OpenVDB tree at index-space points: bit for bit the
/// values of openvdb::tools::BoxSampler, faster where reads follow each other
/// through the same leaf (a ray march, a pass over a leaf's voxels).
/// BoxSampler asks the accessor for each of the eight corners; this reads them
/// straight from the leaf's buffer whenever the 2 x 2 x 2 corners lie in one
/// leaf (343 of a leaf's 512 cells), and keeps that leaf for the next read.
///
/// Holds its own accessor: one sampler per thread, like an accessor. The
/// accessor is not registered with the tree (OpenVDB's IsSafe = false): the
/// tree must not change while the sampler reads it, and a sampler costs
/// nothing to make, so one per ray or per task is free (a registered one
/// takes a lock on the tree's shared table of accessors, made and dropped).

#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>

#include <limits>

namespace vfield {

template<typename TreeT>
class TrilinearSampler {
public:
    using ValueType = typename TreeT::ValueType;

    explicit TrilinearSampler(const TreeT& tree) : mAccessor(tree) {}

    /// The tree's value at an index-space point, interpolated as BoxSampler::sample does.
    ValueType atIndex(const openvdb::Vec3d& xyz)
    {
        const openvdb::Vec3i base = openvdb::tools::local_util::floorVec3(xyz);
        const openvdb::Vec3d uvw = xyz - base;
        const openvdb::Coord ijk(base);
        ValueType data[2][2][2];
        constexpr int kLast = int(LeafT::DIM) - 1;
        if ((ijk.x() & kLast) != kLast && (ijk.y() & kLast) != kLast && (ijk.z() & kLast) != kLast) {
            const openvdb::Coord origin = ijk & ~kLast;
            if (origin != mLeafOrigin) {
                mLeaf = mAccessor.probeConstLeaf(ijk);
                mLeafOrigin = origin;
            }
            if (mLeaf) {
                const ValueType* values = mLeaf->buffer().data();
                constexpr openvdb::Index kX = LeafT::DIM * LeafT::DIM, kY = LeafT::DIM;
                const openvdb::Index n = LeafT::coordToOffset(ijk);
                data[0][0][0] = values[n];
                data[0][0][1] = values[n + 1];
                data[0][1][0] = values[n + kY];
                data[0][1][1] = values[n + kY + 1];
                data[1][0][0] = values[n + kX];
                data[1][0][1] = values[n + kX + 1];
                data[1][1][0] = values[n + kX + kY];
                data[1][1][1] = values[n + kX + kY + 1];
            } else { // a tile or the background: one value over the whole leaf's box
                const ValueType value = mAccessor.getValue(ijk);
                for (auto& plane : data)
                    for (auto& row : plane) row[0] = row[1] = value;
            }
        } else {
            openvdb::tools::BoxSampler::getValues(data, mAccessor, ijk);
        }
        return openvdb::tools::BoxSampler::trilinearInterpolation(data, uvw);
    }

    /// The value of one voxel, as the tree's accessor reads it.
    ValueType valueAt(const openvdb::Coord& ijk) { return mAccessor.getValue(ijk); }

private:
    using LeafT = typename TreeT::LeafNodeType;

    openvdb::tree::ValueAccessor<const TreeT, /*IsSafe=*/false> mAccessor;
    const LeafT* mLeaf = nullptr;
    openvdb::Coord mLeafOrigin{std::numeric_limits<openvdb::Int32>::max()}; ///< of mLeaf; none read yet
};

} // namespace vfield
