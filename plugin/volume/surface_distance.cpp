#include "surface_distance.h"

#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace vfield {

namespace {

/// The leaves around one leaf of a tree, 3 x 3 x 3, null where there is
/// none: a voxel's neighbours are read from them without descending the
/// tree.
template<typename TreeT>
struct LeafNeighbourhood {
    using LeafT = typename TreeT::LeafNodeType;
    static constexpr int kDim = int(LeafT::DIM);
    std::array<LeafT*, 27> leaves{};

    LeafNeighbourhood(TreeT& tree, const openvdb::Coord& origin)
    {
        for (int n = 0; n < 27; ++n)
            leaves[std::size_t(n)] =
                tree.probeLeaf(origin.offsetBy((n / 9 - 1) * kDim, (n / 3 % 3 - 1) * kDim, (n % 3 - 1) * kDim));
    }
    /// The leaf holding voxel (x, y, z), each coordinate in -1..kDim from
    /// the middle leaf's origin, and the voxel's offset in that leaf.
    std::pair<LeafT*, openvdb::Index> at(int x, int y, int z) const
    {
        const auto slot = [](int v) { return v < 0 ? 0 : v < kDim ? 1 : 2; };
        LeafT* leaf = leaves[std::size_t(slot(x) * 9 + slot(y) * 3 + slot(z))];
        return {leaf, LeafT::coordToOffset(openvdb::Coord(x & (kDim - 1), y & (kDim - 1), z & (kDim - 1)))};
    }
};

} // namespace

/// Next to the surface, in the voxels with a face neighbour across it, the
/// distance d to it comes from the density along each axis, as fast
/// sweeping starts (OpenVDB's fogToSdf), and the closest point lies along
/// the density's gradient. From there, layer by layer, each voxel takes the
/// nearest of its neighbours' closest points (a vector distance transform
/// grown as a front, after Danielsson), out to `outward` and in to
/// `inward`: one pass gives both, where sweeping the distance over those
/// voxels (tools::maskSdf), then the offsets to the rest positions along it
/// (tools::sdfToExt), makes two passes that would dominate the detail's cost.
///
/// Only from next to the surface: the splat's faint fringe (its kernels'
/// tails, sparse particles torn off the cloud) spreads far beyond it, and
/// within the fringe's voxels, around their gaps, the density's gradient
/// points anywhere, or nowhere in specks with no surface of their own.
/// Grown from the whole fringe, the layers' closest points would be false
/// surfaces far off the cloud, and the detail would draw lumps there; the
/// fringe can also hold a large share of the density's voxels, all of them
/// to sweep for nothing.
SurfaceDistance::SurfaceDistance(const openvdb::FloatGrid& density, float surfaceDensity, double inward, double outward)
    : distance(openvdb::FloatGrid::create(std::numeric_limits<float>::max())), closest(openvdb::Vec3SGrid::create())
{
    const double voxel = density.voxelSize()[0];
    distance->setTransform(density.transform().copy());
    closest->setTransform(density.transform().copy());
    const auto isInside = [surfaceDensity](float rho) { return rho > surfaceDensity; };
    // The distance to the surface in voxels, from a voxel's face neighbours
    // across it (linear between the two), or infinity where none is across.
    const auto distanceAcross = [&](const openvdb::FloatGrid::ConstAccessor& densityAt, const openvdb::Coord& c, float rho) {
        double sum = 0.0;
        for (int axis = 0; axis < 3; ++axis) {
            double nearest = std::numeric_limits<double>::infinity();
            for (const int side : {-1, 1}) {
                openvdb::Coord n = c;
                n[axis] += side;
                const float across = densityAt.getValue(n);
                if (isInside(across) != isInside(rho))
                    nearest = std::min(nearest, double(rho - surfaceDensity) / double(rho - across));
            }
            if (nearest < std::numeric_limits<double>::infinity()) sum += 1.0 / std::max(nearest * nearest, 1e-12);
        }
        return sum > 0.0 ? 1.0 / std::sqrt(sum) : std::numeric_limits<double>::infinity();
    };
    openvdb::MaskTree inside(density.tree(), false, openvdb::TopologyCopy());
    openvdb::MaskTree known(density.tree(), false, openvdb::TopologyCopy());
    openvdb::tree::LeafManager<openvdb::MaskTree>(known).foreach ([&](openvdb::MaskTree::LeafNodeType& leaf, std::size_t) {
        const auto densityAt = density.getConstAccessor();
        openvdb::MaskTree::LeafNodeType& insideLeaf = *inside.probeLeaf(leaf.origin());
        for (auto v = leaf.beginValueOn(); v; ++v) {
            const float rho = densityAt.getValue(v.getCoord());
            if (!isInside(rho)) insideLeaf.setValueOff(v.pos());
            if (!(distanceAcross(densityAt, v.getCoord(), rho) < std::numeric_limits<double>::infinity()))
                leaf.setValueOff(v.pos());
        }
    });
    openvdb::tools::pruneInactive(known);
    openvdb::tools::pruneInactive(inside);
    openvdb::MaskTree front(known, false, openvdb::TopologyCopy());
    closest->tree().topologyUnion(known);
    distance->tree().topologyUnion(known);
    openvdb::tree::LeafManager<openvdb::MaskTree>(known).foreach ([&](const openvdb::MaskTree::LeafNodeType& leaf, std::size_t) {
        const auto densityAt = density.getConstAccessor();
        openvdb::Vec3STree::LeafNodeType& closestLeaf = *closest->tree().probeLeaf(leaf.origin());
        openvdb::FloatTree::LeafNodeType& distanceLeaf = *distance->tree().probeLeaf(leaf.origin());
        for (auto v = leaf.cbeginValueOn(); v; ++v) {
            const openvdb::Coord c = v.getCoord();
            const float rho = densityAt.getValue(c);
            // Signed, negative inside: the surface lies down the density's
            // gradient from outside and up it from inside.
            const double d = (isInside(rho) ? -1.0 : 1.0) * distanceAcross(densityAt, c, rho);
            openvdb::Vec3d gradient;
            for (int axis = 0; axis < 3; ++axis) {
                openvdb::Coord below = c, above = c;
                --below[axis];
                ++above[axis];
                gradient[axis] = 0.5 * (double(densityAt.getValue(above)) - double(densityAt.getValue(below)));
            }
            const double length = gradient.length();
            closestLeaf.setValueOnly(
                v.pos(), openvdb::Vec3s(c.asVec3d() + (length > 0.0 ? gradient * (d / length) : openvdb::Vec3d(0.0))));
            distanceLeaf.setValueOnly(v.pos(), float(d * voxel));
        }
    });

    // A layer reads only the voxels of the layers before it, finished, and
    // each of its voxels is written by one task, without changing the trees:
    // the same for any thread count. Inside the surface, negative.
    while (!front.empty()) {
        openvdb::tools::dilateActiveValues(front, 1, openvdb::tools::NN_FACE_EDGE_VERTEX, openvdb::tools::IGNORE_TILES);
        front.topologyDifference(known);
        // The layer's voxels made first: the tasks then only fill in values.
        closest->tree().topologyUnion(front);
        distance->tree().topologyUnion(front);
        openvdb::tree::LeafManager<openvdb::MaskTree>(front).foreach (
            [&](const openvdb::MaskTree::LeafNodeType& leaf, std::size_t) {
                const LeafNeighbourhood<openvdb::MaskTree> knownAround(known, leaf.origin());
                const LeafNeighbourhood<openvdb::Vec3STree> closestAround(closest->tree(), leaf.origin());
                openvdb::FloatTree::LeafNodeType& distanceLeaf = *distance->tree().probeLeaf(leaf.origin());
                const openvdb::MaskTree::LeafNodeType* insideLeaf = inside.probeConstLeaf(leaf.origin());
                const openvdb::MaskTree::LeafNodeType* knownHere = knownAround.leaves[13];
                const openvdb::Vec3STree::LeafNodeType* closestHere = closestAround.leaves[13];
                constexpr int kDim = int(openvdb::MaskTree::LeafNodeType::DIM);
                for (auto v = leaf.cbeginValueOn(); v; ++v) {
                    const openvdb::Coord local = v.getCoord() - leaf.origin();
                    double nearest = std::numeric_limits<double>::infinity();
                    openvdb::Vec3s best(0.0f);
                    const auto consider = [&](const openvdb::Vec3s& candidate) {
                        const double squared = (openvdb::Vec3d(candidate) - v.getCoord().asVec3d()).lengthSqr();
                        if (squared < nearest) {
                            nearest = squared;
                            best = candidate;
                        }
                    };
                    // A voxel off the leaf's faces has its 26 neighbours in
                    // the leaf itself: read at offsets from its own, without
                    // finding each one's leaf. The same candidates in the
                    // same order.
                    const bool offFaces = local.x() > 0 && local.x() < kDim - 1 && local.y() > 0 && local.y() < kDim - 1 &&
                                          local.z() > 0 && local.z() < kDim - 1;
                    if (offFaces && knownHere) {
                        const int here = int(v.pos());
                        for (int dx = -1; dx <= 1; ++dx)
                            for (int dy = -1; dy <= 1; ++dy)
                                for (int dz = -1; dz <= 1; ++dz) {
                                    const auto offset = openvdb::Index(here + (dx * kDim + dy) * kDim + dz);
                                    if (knownHere->isValueOn(offset)) consider(closestHere->getValue(offset));
                                }
                    } else {
                        for (int dx = -1; dx <= 1; ++dx)
                            for (int dy = -1; dy <= 1; ++dy)
                                for (int dz = -1; dz <= 1; ++dz) {
                                    const int x = local.x() + dx, y = local.y() + dy, z = local.z() + dz;
                                    const auto [knownLeaf, offset] = knownAround.at(x, y, z);
                                    if (knownLeaf && knownLeaf->isValueOn(offset))
                                        consider(closestAround.at(x, y, z).first->getValue(offset));
                                }
                    }
                    closestAround.leaves[13]->setValueOnly(v.pos(), best);
                    const double d = std::sqrt(nearest) * voxel;
                    distanceLeaf.setValueOnly(v.pos(), float(insideLeaf && insideLeaf->isValueOn(v.pos()) ? -d : d));
                }
            });
        known.topologyUnion(front);
        // The next layer grows from this one's voxels within the band.
        openvdb::tree::LeafManager<openvdb::MaskTree>(front).foreach ([&](openvdb::MaskTree::LeafNodeType& leaf, std::size_t) {
            const openvdb::FloatTree::LeafNodeType& distances = *distance->tree().probeConstLeaf(leaf.origin());
            for (auto v = leaf.beginValueOn(); v; ++v) {
                const double d = distances.getValue(v.pos());
                if (d > outward || d < -inward) leaf.setValueOff(v.pos());
            }
        });
        openvdb::tools::pruneInactive(front);
    }
    // Deeper inside than the layers reach: inside whatever the octaves.
    inside.topologyDifference(known);
    distance->tree().topologyUnion(inside);
    openvdb::tree::LeafManager<openvdb::MaskTree>(inside).foreach ([&](const openvdb::MaskTree::LeafNodeType& leaf, std::size_t) {
        openvdb::FloatTree::LeafNodeType& distanceLeaf = *distance->tree().probeLeaf(leaf.origin());
        for (auto v = leaf.cbeginValueOn(); v; ++v) distanceLeaf.setValueOnly(v.pos(), -std::numeric_limits<float>::max());
    });
}

} // namespace vfield
