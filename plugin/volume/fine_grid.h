#pragma once
/// @file fine_grid.h
/// What the detail styles share, within libvfield's volume stage: the rest
/// positions their noise is drawn at, and the grid finer than the splat's
/// that the detailed density is resampled on, read from the splat's voxels
/// by trilinear taps.

#include <vfield/core/vdb_trees.h>
#include <vfield/volume/density_splat.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <memory>
#include <vector>

namespace vfield {

/// At most two rest positions a particle's detail is drawn at (dual rest).
constexpr int kMaxRests = 2;

/// One rest position the detail is drawn at, and how much of it.
struct RestChannel {
    const std::vector<Vec3f>* positions = nullptr;
    float weight = 1.0f;
    /// Added to the noise's coordinates: the second rest draws from another
    /// part of the noise, so the two are independent and their blend keeps the
    /// noise's contrast when normalized (see detailedDensity).
    openvdb::Vec3f noiseOffset{0.0f};
};

/// 3t^2 - 2t^3 of x clamped to [0, 1].
inline double smoothstep01(double x)
{
    const double t = std::clamp(x, 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

/// How many detail voxels span one of the splat's.
int fineRatio(const openvdb::FloatGrid& density, double detailVoxelSize);

/// The transform of a grid `ratio` times finer than `density`'s: fine voxel
/// ratio c + k (k = 0..ratio-1) lies inside coarse voxel c, its centre at
/// c + (k - (ratio - 1) / 2) / ratio coarse voxels.
openvdb::math::Transform::Ptr finerTransform(const openvdb::FloatGrid& density, int ratio);

/// The active voxels of `grid`'s topology, in its index space.
openvdb::MaskGrid::Ptr topologyOf(const openvdb::FloatGrid& grid);

/// Two independent noises blended with weights a and b have a standard
/// deviation sqrt(a^2 + b^2) of one: dividing by it keeps the contrast
/// through the blend of the rest channels.
float inverseBlendNorm(const std::vector<RestChannel>& channels);

/// A grid `ratio` times finer than `density` (finerTransform) over the
/// coarse voxels active in `coarse`. makeBlock() gives each task its own
/// block(c, values) (samplers keep accessors), which sets the ratio^3 fine
/// voxels inside coarse voxel c, values[(i ratio + j) ratio + k] that of
/// fine voxel ratio c + (i, j, k); those not above 0 are left out. Each
/// coarse voxel is computed on its own, so the grid is the same for any
/// thread count.
template<typename MakeBlock>
openvdb::FloatGrid::Ptr resampleFiner(const openvdb::FloatGrid& density, const openvdb::MaskGrid& coarse, int ratio,
                                      const MakeBlock& makeBlock)
{
    std::vector<const openvdb::MaskTree::LeafNodeType*> coarseLeaves;
    for (auto leaf = coarse.tree().cbeginLeaf(); leaf; ++leaf) coarseLeaves.push_back(leaf.getLeaf());
    using FineLeaf = openvdb::FloatTree::LeafNodeType;
    std::vector<std::vector<std::unique_ptr<FineLeaf>>> fineLeaves(coarseLeaves.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, coarseLeaves.size()), [&](const tbb::blocked_range<std::size_t>& range) {
        auto block = makeBlock();
        std::vector<double> values(std::size_t(ratio * ratio * ratio));
        for (std::size_t n = range.begin(); n != range.end(); ++n) {
            std::map<openvdb::Coord, std::unique_ptr<FineLeaf>> leaves; // ordered: added to the tree in a fixed order
            FineLeaf* current = nullptr; // the last voxel's: most voxels share their neighbour's leaf
            for (auto voxel = coarseLeaves[n]->cbeginValueOn(); voxel; ++voxel) {
                const openvdb::Coord c = voxel.getCoord();
                block(c, values.data());
                const double* value = values.data();
                for (int i = 0; i < ratio; ++i)
                    for (int j = 0; j < ratio; ++j)
                        for (int k = 0; k < ratio; ++k, ++value) {
                            if (!(*value > 0.0)) continue;
                            const openvdb::Coord f(ratio * c.x() + i, ratio * c.y() + j, ratio * c.z() + k);
                            const openvdb::Coord origin = f & ~int32_t(FineLeaf::DIM - 1);
                            if (!current || current->origin() != origin) {
                                std::unique_ptr<FineLeaf>& leaf = leaves[origin];
                                if (!leaf) leaf = std::make_unique<FineLeaf>(f, 0.0f, false);
                                current = leaf.get();
                            }
                            current->setValueOn(f, float(*value));
                        }
            }
            for (auto& [origin, leaf] : leaves) fineLeaves[n].push_back(std::move(leaf));
        }
    });
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    grid->setTransform(finerTransform(density, ratio));
    for (auto& leaves : fineLeaves)
        for (auto& leaf : leaves) grid->tree().addLeaf(leaf.release());
    return grid;
}

/// Trilinear interpolation at the fine voxels inside a coarse voxel from its
/// 3x3x3 neighbourhood of values, read once for all of them: along each
/// axis, fine voxel k lies between neighbours lower[k] and lower[k] + 1
/// (0, 1, 2: the coarse voxel's left neighbour, itself, its right one).
class FineTaps {
public:
    explicit FineTaps(int ratio) : mLower(std::size_t(ratio)), mUpperWeight(std::size_t(ratio)), mOffset(std::size_t(ratio))
    {
        for (int k = 0; k < ratio; ++k) {
            const double t = (double(k) - 0.5 * double(ratio - 1)) / double(ratio);
            mOffset[std::size_t(k)] = t;
            mLower[std::size_t(k)] = t < 0.0 ? 0 : 1;
            mUpperWeight[std::size_t(k)] = t < 0.0 ? t + 1.0 : t;
        }
    }
    /// Fine voxel k's centre from its coarse voxel's, in coarse voxels.
    double offset(int k) const { return mOffset[std::size_t(k)]; }

    /// The value at fine voxel (i, j, k) of a coarse voxel whose neighbourhood is n.
    template<typename ValueT>
    ValueT at(const ValueT (&n)[3][3][3], int i, int j, int k) const
    {
        const int x = mLower[std::size_t(i)], y = mLower[std::size_t(j)], z = mLower[std::size_t(k)];
        const double u = mUpperWeight[std::size_t(i)], v = mUpperWeight[std::size_t(j)], w = mUpperWeight[std::size_t(k)];
        const auto lerp = [](const ValueT& a, const ValueT& b, double t) { return ValueT(a + (b - a) * t); };
        const auto alongZ = [&](int dx, int dy) { return lerp(n[x + dx][y + dy][z], n[x + dx][y + dy][z + 1], w); };
        return lerp(lerp(alongZ(0, 0), alongZ(0, 1), v), lerp(alongZ(1, 0), alongZ(1, 1), v), u);
    }

private:
    std::vector<int> mLower;
    std::vector<double> mUpperWeight, mOffset;
};

/// The values of one leaf's box of a tree and of the layer of voxels around
/// it (10 x 10 x 10), copied from the 27 leaves there when a voxel of another
/// leaf is asked for: the 3x3x3 neighbourhoods of a leaf's voxels are read
/// from memory, not by 27 accessor reads each.
template<typename TreeT>
class LeafHalo {
public:
    using ValueT = typename TreeT::ValueType;

    explicit LeafHalo(const TreeT& tree) : mAccessor(tree) {}

    /// The 3x3x3 neighbourhood of voxel c, n[1][1][1] its own value: what
    /// the tree's accessor reads there.
    template<typename OutT>
    void neighbourhood(const openvdb::Coord& c, OutT (&n)[3][3][3])
    {
        const openvdb::Coord origin = c & ~(kDim - 1);
        if (origin != mOrigin) load(origin);
        const openvdb::Coord local = c - origin; // the halo's voxel (local + 1) is c
        for (int dx = 0; dx < 3; ++dx)
            for (int dy = 0; dy < 3; ++dy)
                for (int dz = 0; dz < 3; ++dz)
                    n[dx][dy][dz] = OutT(mValues[index(local.x() + dx, local.y() + dy, local.z() + dz)]);
    }

private:
    using LeafT = typename TreeT::LeafNodeType;
    static constexpr int kDim = int(LeafT::DIM), kSide = kDim + 2;
    static int index(int x, int y, int z) { return (x * kSide + y) * kSide + z; }

    void load(const openvdb::Coord& origin)
    {
        mOrigin = origin;
        // Each of the 27 leaves' values, or the one value over its box (a tile's or the background).
        const LeafT* leaves[27];
        ValueT tiles[27];
        for (int n = 0; n < 27; ++n) {
            const openvdb::Coord at = origin.offsetBy((n / 9 - 1) * kDim, (n / 3 % 3 - 1) * kDim, (n % 3 - 1) * kDim);
            leaves[n] = mAccessor.probeConstLeaf(at);
            if (!leaves[n]) tiles[n] = mAccessor.getValue(at);
        }
        const auto slot = [](int v) { return v < 0 ? 0 : v < kDim ? 1 : 2; };
        for (int x = -1; x <= kDim; ++x)
            for (int y = -1; y <= kDim; ++y)
                for (int z = -1; z <= kDim; ++z) {
                    const int n = slot(x) * 9 + slot(y) * 3 + slot(z);
                    mValues[index(x + 1, y + 1, z + 1)] =
                        leaves[n] ? leaves[n]->getValue(openvdb::Coord(x & (kDim - 1), y & (kDim - 1), z & (kDim - 1)))
                                  : tiles[n];
                }
    }

    openvdb::tree::ValueAccessor<const TreeT, /*IsSafe=*/false> mAccessor;
    openvdb::Coord mOrigin{std::numeric_limits<openvdb::Int32>::max()}; ///< of the leaf loaded; none yet
    std::array<ValueT, kSide * kSide * kSide> mValues;
};

} // namespace vfield
