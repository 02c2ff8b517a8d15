#pragma once
/// @file trilinear_sampler.h
/// Trilinear reads of an OpenVDB tree at index-space points: bit for bit the
/// values of openvdb::tools::BoxSampler, faster where reads follow each other
/// through the same leaves (a ray march, a pass over a leaf's voxels, a cloud
/// of particles in spatial order). BoxSampler asks the accessor for each of
/// the eight corners, and the accessor keeps one leaf; this reads them
/// straight from the leaves' buffers, and keeps the leaf holding the cell's
/// first corner and the neighbours after it along each axis that cells
/// straddling its faces read (the cells of a leaf's last row, column and
/// layer, 169 of its 512, take their corners from two, four or eight leaves).
///
/// Holds its own accessor: one sampler per thread, like an accessor. The
/// accessor is not registered with the tree (OpenVDB's IsSafe = false): the
/// tree must not change while the sampler reads it, and a sampler costs
/// nothing to make, so one per ray or per task is free (a registered one
/// takes a lock on the tree's shared table of accessors, made and dropped).

#include <vfield/core/vdb_trees.h>

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
        const openvdb::Coord origin = enterLeaf(ijk);
        ValueType data[2][2][2];
        const openvdb::Coord local = ijk - origin;
        if (local.x() != kLast && local.y() != kLast && local.z() != kLast) {
            const Neighbour& leaf = neighbour(0);
            if (leaf.values) {
                constexpr openvdb::Index kX = LeafT::DIM * LeafT::DIM, kY = LeafT::DIM;
                const ValueType* values = leaf.values + LeafT::coordToOffset(ijk);
                data[0][0][0] = values[0];
                data[0][0][1] = values[1];
                data[0][1][0] = values[kY];
                data[0][1][1] = values[kY + 1];
                data[1][0][0] = values[kX];
                data[1][0][1] = values[kX + 1];
                data[1][1][0] = values[kX + kY];
                data[1][1][1] = values[kX + kY + 1];
            } else { // a tile or the background: one value over the whole leaf's box
                for (auto& plane : data)
                    for (auto& row : plane) row[0] = row[1] = leaf.tile;
            }
        } else {
            for (int i = 0; i < 2; ++i)
                for (int j = 0; j < 2; ++j)
                    for (int k = 0; k < 2; ++k) {
                        const openvdb::Coord corner = ijk.offsetBy(i, j, k);
                        // Past the last voxel along an axis: the next leaf along it.
                        const int slot =
                            (local.x() + i > kLast ? 4 : 0) | (local.y() + j > kLast ? 2 : 0) | (local.z() + k > kLast ? 1 : 0);
                        const Neighbour& leaf = neighbour(slot);
                        data[i][j][k] = leaf.values ? leaf.values[LeafT::coordToOffset(corner)] : leaf.tile;
                    }
        }
        return openvdb::tools::BoxSampler::trilinearInterpolation(data, uvw);
    }

    /// The value of one voxel, as the tree's accessor reads it, from the
    /// leaf atIndex keeps: reads through the same leaf, or the same tile's
    /// leaf-sized box, find it without descending the tree (the accessor
    /// keeps no tile, so it descends for every read in a tile).
    ValueType valueAt(const openvdb::Coord& ijk)
    {
        enterLeaf(ijk);
        const Neighbour& leaf = neighbour(0);
        return leaf.values ? leaf.values[LeafT::coordToOffset(ijk)] : leaf.tile;
    }

private:
    using LeafT = typename TreeT::LeafNodeType;
    static constexpr int kLast = int(LeafT::DIM) - 1; ///< a leaf's last voxel along an axis, from its origin

    /// A leaf's values, or where it has none, the one value over its box (a tile's or the background).
    struct Neighbour {
        const ValueType* values = nullptr;
        ValueType tile{};
    };

    /// Makes the leaf holding ijk slot 0's, forgetting the neighbours probed
    /// around another; returns its origin.
    openvdb::Coord enterLeaf(const openvdb::Coord& ijk)
    {
        const openvdb::Coord origin = ijk & ~kLast;
        if (origin != mOrigin) {
            mOrigin = origin;
            mProbed = 0;
        }
        return origin;
    }

    /// The leaf at mOrigin offset by a leaf along x, y and z as slot's bits
    /// 4, 2 and 1 say, probed at its first use since mOrigin changed.
    const Neighbour& neighbour(int slot)
    {
        Neighbour& n = mNeighbours[slot];
        if (!(mProbed & (1u << slot))) {
            constexpr int dim = int(LeafT::DIM);
            const openvdb::Coord at = mOrigin.offsetBy(slot & 4 ? dim : 0, slot & 2 ? dim : 0, slot & 1 ? dim : 0);
            const LeafT* leaf = mAccessor.probeConstLeaf(at);
            n.values = leaf ? leaf->buffer().data() : nullptr;
            if (!leaf) n.tile = mAccessor.getValue(at);
            mProbed |= 1u << slot;
        }
        return n;
    }

    openvdb::tree::ValueAccessor<const TreeT, /*IsSafe=*/false> mAccessor;
    openvdb::Coord mOrigin{std::numeric_limits<openvdb::Int32>::max()}; ///< of the leaf in slot 0; none read yet
    Neighbour mNeighbours[8];
    unsigned mProbed = 0; ///< bit `slot`: mNeighbours[slot] is probed
};

} // namespace vfield
