#include <vfield/render/optical_depth_map.h>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace vfield {

namespace {
using DepthLeaf = openvdb::FloatTree::LeafNodeType;
constexpr int kLeafDim = int(DepthLeaf::DIM);
/// The slices Reader::at walks along a point's own way across a cloud's lit edge, at most.
constexpr int kMaxEdgeSteps = 8;
} // namespace

OpticalDepthMap::OpticalDepthMap(openvdb::FloatGrid::ConstPtr densityGrid, const Vec3d& towardsLight)
    : mDensity(std::move(densityGrid))
{
    const openvdb::FloatGrid& density = *mDensity;
    mAlong = -towardsLight.unitSafe();
    mAcross1 = (std::abs(mAlong[1]) < 0.9 ? Vec3d(0, 1, 0) : Vec3d(1, 0, 0)).cross(mAlong).unitSafe();
    mAcross2 = mAlong.cross(mAcross1);
    const double spacing = density.voxelSize()[0];
    mInverseSpacing = 1.0 / spacing;

    // The lattice's leaves over every point where the density is not zero:
    // within a voxel of an active one, where trilinear reads reach.
    openvdb::MaskTree active(density.tree(), false, openvdb::TopologyCopy());
    active.voxelizeActiveTiles();
    std::vector<const openvdb::MaskTree::LeafNodeType*> activeLeaves;
    active.getNodes(activeLeaves);
    tbb::enumerable_thread_specific<openvdb::MaskTree> touchedPerThread;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, activeLeaves.size()), [&](const tbb::blocked_range<std::size_t>& r) {
        openvdb::tree::ValueAccessor<openvdb::MaskTree> touched(touchedPerThread.local());
        for (std::size_t n = r.begin(); n != r.end(); ++n) {
            // The box of the leaf's active voxels, not the whole leaf's: in a
            // cloud's faint fringe most leaves hold a few voxels, and whole
            // leaves would make the maps' lattices much larger.
            openvdb::CoordBBox voxels;
            activeLeaves[n]->evalActiveBoundingBox(voxels);
            const openvdb::Vec3d from = voxels.min().asVec3d() - 1.0, to = voxels.max().asVec3d() + 1.0;
            Vec3d lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
            for (int c = 0; c < 8; ++c) {
                const Vec3d corner(c & 1 ? to[0] : from[0], c & 2 ? to[1] : from[1], c & 4 ? to[2] : from[2]);
                const Vec3d lattice = indexOf(density.transform().indexToWorld(corner));
                lo = minComponent(lo, lattice);
                hi = maxComponent(hi, lattice);
            }
            // A point's trilinear read takes the lattice points floor(x) and floor(x) + 1.
            const openvdb::Coord first = openvdb::Coord::floor(lo) & ~(kLeafDim - 1),
                                 last = (openvdb::Coord::floor(hi) + openvdb::Coord(1)) & ~(kLeafDim - 1);
            for (int i = first.x(); i <= last.x(); i += kLeafDim)
                for (int j = first.y(); j <= last.y(); j += kLeafDim)
                    for (int k = first.z(); k <= last.z(); k += kLeafDim)
                        touched.touchLeaf(openvdb::Coord(i, j, k))->setValuesOn();
        }
    });
    openvdb::MaskTree touched;
    for (openvdb::MaskTree& part : touchedPerThread) touched.topologyUnion(part);
    // Each column of leaves whole from its first leaf on the light's side to
    // its last: a point between two clouds, where a sample's march towards
    // the light ends, reads the depth of the one nearer the light. Read
    // where the map holds no leaf, it would be none.
    {
        std::vector<const openvdb::MaskTree::LeafNodeType*> touchedLeaves;
        touched.getNodes(touchedLeaves);
        std::vector<openvdb::Coord> sorted(touchedLeaves.size());
        std::transform(touchedLeaves.begin(), touchedLeaves.end(), sorted.begin(),
                       [](const auto* leaf) { return leaf->origin(); });
        std::sort(sorted.begin(), sorted.end());
        for (std::size_t n = 1; n < sorted.size(); ++n)
            if (sorted[n].x() == sorted[n - 1].x() && sorted[n].y() == sorted[n - 1].y())
                for (int k = sorted[n - 1].z() + kLeafDim; k < sorted[n].z(); k += kLeafDim)
                    touched.touchLeaf(openvdb::Coord(sorted[n].x(), sorted[n].y(), k))->setValuesOn();
    }
    mDepth = std::make_shared<openvdb::FloatTree>(touched, 0.0f, openvdb::TopologyCopy());
    std::vector<DepthLeaf*> leaves;
    mDepth->getNodes(leaves);
    // Sorted by (x, y, z): each column of leaves together, from the light's side.
    std::sort(leaves.begin(), leaves.end(), [](const DepthLeaf* a, const DepthLeaf* b) { return a->origin() < b->origin(); });
    std::vector<std::size_t> columnStarts;
    for (std::size_t n = 0; n < leaves.size(); ++n)
        if (n == 0 || leaves[n]->origin().x() != leaves[n - 1]->origin().x() ||
            leaves[n]->origin().y() != leaves[n - 1]->origin().y())
            columnStarts.push_back(n);
    columnStarts.push_back(leaves.size());

    // The density's index of a lattice point. A linear transform's
    // worldToIndex is affine: stepped along the lattice's axes, without a
    // virtual call and a matrix product at every point.
    const openvdb::math::Transform& densityTransform = density.transform();
    const bool linear = densityTransform.isLinear();
    const Vec3d indexOrigin = densityTransform.worldToIndex(Vec3d(0.0)),
                indexAcross1 = densityTransform.worldToIndex(mAcross1 * spacing) - indexOrigin,
                indexAcross2 = densityTransform.worldToIndex(mAcross2 * spacing) - indexOrigin,
                indexAlong = densityTransform.worldToIndex(mAlong * spacing) - indexOrigin;
    const auto densityIndexOf = [&](const openvdb::Coord& ijk) {
        if (!linear) return densityTransform.worldToIndex((mAcross1 * ijk.x() + mAcross2 * ijk.y() + mAlong * ijk.z()) * spacing);
        return indexOrigin + indexAcross1 * ijk.x() + indexAcross2 * ijk.y() + indexAlong * ijk.z();
    };
    // Down each column of lattice points, trapezoids between them.
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, columnStarts.size() - 1), [&](const tbb::blocked_range<std::size_t>& r) {
        TrilinearSampler<openvdb::FloatTree> densityAt(density.tree());
        for (std::size_t column = r.begin(); column != r.end(); ++column) {
            double depth[kLeafDim][kLeafDim] = {}, previous[kLeafDim][kLeafDim] = {};
            for (std::size_t n = columnStarts[column]; n != columnStarts[column + 1]; ++n) {
                const openvdb::Coord& origin = leaves[n]->origin();
                for (int z = 0; z < kLeafDim; ++z)
                    for (int x = 0; x < kLeafDim; ++x)
                        for (int y = 0; y < kLeafDim; ++y) {
                            const openvdb::Coord ijk = origin.offsetBy(x, y, z);
                            const double rho = densityAt.atIndex(densityIndexOf(ijk));
                            depth[x][y] += 0.5 * spacing * (previous[x][y] + rho);
                            previous[x][y] = rho;
                            leaves[n]->setValueOnly(ijk, float(depth[x][y]));
                        }
            }
        }
    });
}

double OpticalDepthMap::Reader::at(const Vec3d& from)
{
    const double spacing = 1.0 / mMap->mInverseSpacing;
    const openvdb::math::Transform& densityTransform = mMap->mDensity->transform();
    Vec3d p = from;
    double depth = 0.0;
    for (int step = 0;; ++step) {
        const Vec3d lattice = mMap->indexOf(p);
        const double slice = std::floor(lattice[2]), toSlice = (lattice[2] - slice) * spacing;
        depth += toSlice * mDensityAt.atIndex(densityTransform.worldToIndex(p - mMap->mAlong * (0.5 * toSlice)));
        p -= mMap->mAlong * toSlice;
        const openvdb::Coord c(int(std::floor(lattice[0])), int(std::floor(lattice[1])), int(slice));
        const float corners[4] = {mDepthAt.valueAt(c), mDepthAt.valueAt(c.offsetBy(1, 0, 0)),
                                  mDepthAt.valueAt(c.offsetBy(0, 1, 0)), mDepthAt.valueAt(c.offsetBy(1, 1, 0))};
        const int lit = int(corners[0] > 0.0f) + int(corners[1] > 0.0f) + int(corners[2] > 0.0f) + int(corners[3] > 0.0f);
        if (lit == 0 || lit == 4 || step == kMaxEdgeSteps) {
            const double u = lattice[0] - c.x(), v = lattice[1] - c.y();
            return depth + (1 - v) * ((1 - u) * corners[0] + u * corners[1]) + v * ((1 - u) * corners[2] + u * corners[3]);
        }
        // On the cloud's lit edge: p's own way, a slice further.
        depth += spacing * mDensityAt.atIndex(densityTransform.worldToIndex(p - mMap->mAlong * (0.5 * spacing)));
        p -= mMap->mAlong * spacing;
    }
}

} // namespace vfield
