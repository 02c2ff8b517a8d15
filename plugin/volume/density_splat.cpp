#include <vfield/volume/density_splat.h>

#include <vfield/core/field_visitors.h>
#include <vfield/core/noise.h>
#include <vfield/core/stopwatch.h>
#include <vfield/core/trilinear_sampler.h>

#include <openvdb/tools/Filter.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tools/Statistics.h>
#include <openvdb/tree/LeafManager.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <memory>

namespace vfield {

void VolumeDetail::validate() const { checkFields(*this); }

double VolumeDetail::displacementRange() const
{
    double octaveSum = 0.0, weight = 1.0;
    for (int octave = 0; octave < octaves; ++octave, weight *= gain) octaveSum += weight;
    return amplitude * octaveSum / frequency;
}

void Condensation::validate() const { checkFields(*this); }

void VolumeOptions::validate() const
{
    checkFields(*this);
    if (voxelSize > 0.0 && kernelRadius > 0.0)
        require(kernelRadius / voxelSize <= kMaxKernelVoxels, "kernelRadius",
                "kernel radius " + numberText(kernelRadius) + " spans more than " + numberText(kMaxKernelVoxels) + " voxels of " +
                    numberText(voxelSize));
    if (voxelSize > 0.0 && detail.enabled() && detail.style == DetailStyle::Displaced)
        require(detail.displacementRange() / voxelSize <= kMaxDisplacementVoxels, "detail/amplitude",
                "the displaced surface moves over " + numberText(detail.displacementRange()) +
                    " world units (amplitude x (1 + gain + ...) / frequency), more than " + numberText(kMaxDisplacementVoxels) +
                    " voxels of " + numberText(voxelSize) + ": lower the amplitude or raise the frequency");
}

VolumeOptions VolumeOptions::resolved(double meanParticleRadius) const
{
    VolumeOptions r = *this;
    if (r.voxelSize == 0.0) r.voxelSize = meanParticleRadius;
    r.kernelRadius = std::max(r.kernelRadius > 0.0 ? r.kernelRadius : 2.0 * meanParticleRadius, r.voxelSize);
    return r;
}

namespace {

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

/// Unnormalized sums over a range of particles: of their deposited weights
/// W, and of W v and W rest, whose ratios to the weights are the mean velocity and
/// rest positions.
struct Splat {
    openvdb::FloatGrid::Ptr weight;
    openvdb::Vec3SGrid::Ptr momentum;
    std::array<openvdb::Vec3SGrid::Ptr, kMaxRests> rest;

    explicit Splat(const openvdb::math::Transform::Ptr& transform)
        : weight(openvdb::FloatGrid::create(0.0f)), momentum(openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f)))
    {
        weight->setTransform(transform);
        momentum->setTransform(transform);
        for (auto& grid : rest) {
            grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
            grid->setTransform(transform);
        }
    }
};

/// Particles per leaf of the fixed reduction tree: the order of float sums
/// depends on this constant only, not on the threads.
constexpr std::size_t kParticlesPerChunk = 16384;
/// A run of particles deposited into one dense box grows while the box holds
/// at most this many voxels, or this many per particle: the box's zeroing and
/// transfer stay small next to the deposit.
constexpr uint64_t kRunVoxels = 4096, kRunVoxelsPerParticle = 16;

/// Dense sums over the box a run of particles deposits into, one array per
/// component so that the innermost loop (along z) is plain arithmetic.
struct DenseSums {
    openvdb::Coord origin, dim;
    std::vector<float> w, vx, vy, vz;
    std::array<std::array<std::vector<float>, 3>, kMaxRests> r; ///< per rest channel, per axis

    /// Zeroes the sums over a new box, those of the first `rests` rest
    /// channels too, keeping the arrays' memory.
    void reset(const openvdb::CoordBBox& box, std::size_t rests)
    {
        origin = box.min();
        dim = box.dim();
        const std::size_t n = std::size_t(dim.x()) * std::size_t(dim.y()) * std::size_t(dim.z());
        for (std::vector<float>* a : {&w, &vx, &vy, &vz}) a->assign(n, 0.0f);
        for (std::size_t c = 0; c < rests; ++c)
            for (auto& axis : r[c]) axis.assign(n, 0.0f);
    }
    std::size_t at(const openvdb::Coord& c) const
    {
        return (std::size_t(c.x() - origin.x()) * std::size_t(dim.y()) + std::size_t(c.y() - origin.y())) * std::size_t(dim.z()) +
               std::size_t(c.z() - origin.z());
    }
};

/// Adds `from`'s leaves into `into` (taking them where `into` has none):
/// work in proportion to the leaves, where tools::compSum visits every
/// entry of both trees' internal nodes (a third of the splat's time).
template<typename TreeT>
void addLeaves(TreeT& into, TreeT& from)
{
    std::vector<typename TreeT::LeafNodeType*> leaves;
    from.stealNodes(leaves);
    for (auto* leaf : leaves) {
        auto* target = into.probeLeaf(leaf->origin());
        if (!target) {
            into.addLeaf(leaf);
            continue;
        }
        for (auto v = leaf->cbeginValueOn(); v; ++v) target->setValueOn(v.pos(), target->getValue(v.pos()) + *v);
        delete leaf;
    }
}

/// Variance along an axis, in voxels squared, of the smooth kernel of radius R
/// voxels, W(r) ~ (1 - r^2/R^2)^3: R^2 / 11.
double smoothKernelVariance(double radiusInVoxels) { return radiusInVoxels * radiusInVoxels / 11.0; }

/// Passes of a 3-voxel mean filter after the trilinear deposit (variance 1/6,
/// each pass adds 2/3) that bring the kernel's spread closest to that of the
/// smooth kernel of the given radius: at least one, so the kernel is four
/// voxels wide and smooth to trilinear reads.
int blurPasses(double radiusInVoxels)
{
    return std::max(1, int(std::lround((smoothKernelVariance(radiusInVoxels) - 1.0 / 6.0) * 1.5)));
}

/// The kernel's weight at its centre, per axis, for a particle at a voxel
/// centre: the middle of [1 1 1]/3 convolved with itself `passes` times.
double centreWeight(int passes)
{
    std::vector<double> weights{1.0};
    for (int pass = 0; pass < passes; ++pass) {
        std::vector<double> next(weights.size() + 2, 0.0);
        for (std::size_t i = 0; i < weights.size(); ++i)
            for (std::size_t j = 0; j < 3; ++j) next[i + j] += weights[i] / 3.0;
        weights = std::move(next);
    }
    return weights[weights.size() / 2];
}

/// OpenVDB's mean filter, `passes` times, over the grid's voxels grown by
/// as many voxels: the blur reaches every voxel it can give a value to.
template<typename GridT>
void blur(GridT& grid, int passes)
{
    openvdb::tools::dilateActiveValues(grid.tree(), passes, openvdb::tools::NN_FACE_EDGE_VERTEX, openvdb::tools::IGNORE_TILES);
    openvdb::tools::Filter<GridT> filter(grid);
    filter.mean(1, passes);
}

double smoothstep01(double x)
{
    const double t = std::clamp(x, 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

/// A fine voxel's density: the splat's density rho shaped by the detail's
/// noise, amplitude x g (DetailStyle).
double shapedDensity(DetailStyle style, double rho, float amplitudeTimesNoise, double softness, double inverseSoftness)
{
    const double ag = double(amplitudeTimesNoise);
    switch (style) {
    case DetailStyle::Erode:
        // The noise scales the edge threshold rather than offsetting it, so a
        // thin fringe is always eroded: no shell of faint density around the cloud.
        return rho * std::max(0.0, 1.0 + 0.5 * ag) * smoothstep01(rho * inverseSoftness * (1.0 + ag));
    case DetailStyle::Billows: {
        // The edge's density: half the softness, but fading with the splat's
        // in its faintest fringe, so that it is zero where the splat's
        // support ends rather than a staircase along its voxels' faces.
        const double edge = std::min(0.5 * softness, 8.0 * rho);
        return std::max(rho, edge) * smoothstep01((rho * inverseSoftness + ag - 0.45) * 10.0);
    }
    case DetailStyle::Displaced:
        break; // displacedDensity
    }
    return rho;
}

/// How many detail voxels span one of the splat's.
int fineRatio(const openvdb::FloatGrid& density, double detailVoxelSize)
{
    return std::max(1, int(std::lround(density.voxelSize()[0] / detailVoxelSize)));
}

/// The transform of a grid `ratio` times finer than `density`'s: fine voxel
/// ratio c + k (k = 0..ratio-1) lies inside coarse voxel c, its centre at
/// c + (k - (ratio - 1) / 2) / ratio coarse voxels.
openvdb::math::Transform::Ptr finerTransform(const openvdb::FloatGrid& density, int ratio)
{
    const double fine = density.voxelSize()[0] / ratio;
    auto transform = openvdb::math::Transform::createLinearTransform(fine);
    transform->postTranslate(openvdb::Vec3d(-0.5 * (ratio - 1) * fine));
    return transform;
}

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
/// from memory, not by 27 accessor reads each (the displaced detail 0.46 ->
/// 0.435 s a frame at the stirred bank's frames 195-200).
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

/// The active voxels of `grid`'s topology, in its index space.
openvdb::MaskGrid::Ptr topologyOf(const openvdb::FloatGrid& grid)
{
    openvdb::MaskGrid::Ptr mask = openvdb::MaskGrid::create(false);
    mask->setTransform(grid.transform().copy());
    mask->topologyUnion(grid);
    return mask;
}

/// Two independent noises blended with weights a and b have a standard
/// deviation sqrt(a^2 + b^2) of one: dividing by it keeps the contrast
/// through the blend of the rest channels.
float inverseBlendNorm(const std::vector<RestChannel>& channels)
{
    double weightNorm = 0.0;
    for (const RestChannel& channel : channels) weightNorm += double(channel.weight) * double(channel.weight);
    return float(1.0 / std::sqrt(weightNorm));
}

/// The density resampled on the detail's finer grid and shaped by noise at
/// the interpolated rest position (DetailStyle::Erode and Billows).
openvdb::FloatGrid::Ptr detailedDensity(const openvdb::FloatGrid& density, const std::vector<openvdb::Vec3SGrid::Ptr>& rests,
                                        const std::vector<RestChannel>& channels, const VolumeDetail& detail, double edgeSoftness)
{
    // Every coarse voxel that trilinear reads can give density: the active ones and their neighbours.
    const openvdb::MaskGrid::Ptr mask = topologyOf(density);
    openvdb::tools::dilateActiveValues(mask->tree(), 1, openvdb::tools::NN_FACE_EDGE_VERTEX, openvdb::tools::IGNORE_TILES);

    const GradientNoise noise(detail.seed);
    const FractalOptions fractal{detail.octaves, 2.0, detail.gain};
    const float frequency = float(detail.frequency), amplitude = float(detail.amplitude);
    const double inverseSoftness = 1.0 / edgeSoftness;
    const float inverseNorm = inverseBlendNorm(channels);
    // Billows: 2 billow - 1, lumps about [-1, 1] as fBm is (billow is within [0, 1]).
    const auto noiseAt = [&](const openvdb::Vec3f& p) {
        return detail.style == DetailStyle::Billows ? 2.0f * billow(noise, p, fractal) - 1.0f : fbm(noise, p, fractal);
    };
    // Billows keep the splat's density wherever rho / edgeSoftness + amplitude
    // g >= 0.55, whatever g: deep inside, where rho / edgeSoftness passes 0.55
    // plus the largest amplitude |g| can reach, the noise changes nothing and
    // is not drawn. Only the cloud's skin pays for it. (The margin covers the
    // float rounding of g.)
    double largestG = 0.0;
    for (const RestChannel& channel : channels) largestG += std::abs(double(channel.weight)) * double(inverseNorm);
    const double noiseFreeAbove = detail.style == DetailStyle::Billows ? 0.55 + double(amplitude) * largestG * (1.0 + 1e-4)
                                                                       : std::numeric_limits<double>::infinity();
    const int ratio = fineRatio(density, detail.voxelSize);
    const openvdb::math::Transform::Ptr fine = finerTransform(density, ratio);
    return resampleFiner(density, *mask, ratio, [&] {
        // The rest grids share the density's transform (the splat's).
        std::vector<TrilinearSampler<openvdb::Vec3STree>> restAt;
        for (const auto& rest : rests) restAt.emplace_back(rest->tree());
        auto valueAt = [&, densityAt = TrilinearSampler<openvdb::FloatTree>(density.tree()),
                        restAt = std::move(restAt)](const openvdb::Vec3d& coarseIndex) mutable {
            const double rho = densityAt.atIndex(coarseIndex);
            if (!(rho > 0.0)) return 0.0;
            float g = 0.0f;
            if (rho * inverseSoftness < noiseFreeAbove)
                for (std::size_t r = 0; r < channels.size(); ++r)
                    g += channels[r].weight *
                         noiseAt(openvdb::Vec3f(restAt[r].atIndex(coarseIndex)) * frequency + channels[r].noiseOffset);
            g *= inverseNorm;
            return shapedDensity(detail.style, rho, amplitude * g, edgeSoftness, inverseSoftness);
        };
        return [&, valueAt = std::move(valueAt)](const openvdb::Coord& c, double* values) mutable {
            for (int i = 0; i < ratio; ++i)
                for (int j = 0; j < ratio; ++j)
                    for (int k = 0; k < ratio; ++k) {
                        const openvdb::Coord f(ratio * c.x() + i, ratio * c.y() + j, ratio * c.z() + k);
                        *values++ = valueAt(density.transform().worldToIndex(fine->indexToWorld(f)));
                    }
        };
    });
}

/// The splat's surface, where its density is surfaceDensity: the signed
/// distance to it (world units, negative inside) and each voxel's closest
/// point on it (index space), over the band of voxels from `inward` inside
/// the surface to `outward` outside it (world units), and the one layer of
/// voxels just beyond it. The density's deeper voxels read -FLT_MAX and
/// have no closest point; nothing farther out is stored.
struct SurfaceDistance {
    openvdb::FloatGrid::Ptr distance;
    openvdb::Vec3SGrid::Ptr closest;

    SurfaceDistance(const openvdb::FloatGrid& density, float surfaceDensity, double inward, double outward);
};

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

/// Next to the surface, in the voxels with a face neighbour across it, the
/// distance d to it comes from the density along each axis, as fast
/// sweeping starts (OpenVDB's fogToSdf), and the closest point lies along
/// the density's gradient. From there, layer by layer, each voxel takes the
/// nearest of its neighbours' closest points (a vector distance transform
/// grown as a front, after Danielsson), out to `outward` and in to
/// `inward`: sweeping the distance over those voxels (tools::maskSdf), then
/// the offsets to the rest positions along it (tools::sdfToExt), took 1.3
/// of the bank's 2.2 s of detail.
///
/// Only from next to the surface: the splat's faint fringe (its kernels'
/// tails, sparse particles torn off the cloud) spreads far beyond it, and
/// fast sweeping measured its distance there within the density's voxels,
/// around their gaps, where its gradient points anywhere, or not at all in
/// specks with no surface of their own. Grown from the whole fringe, the
/// layers' closest points were false surfaces up to 40 units off the cloud
/// and drew lumps there (the stirred bank's frame 210: 5.1 M voxels in all,
/// 2.0 M of them over 30 units out, 16,000 inside); sweeping it took 0.17 of
/// the stirred bank's 1.3 s at frame 120.
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
                    // finding each one's leaf (the detail stage 0.44 -> 0.42
                    // s a frame at the main job's frames 196-200). The same
                    // candidates in the same order.
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

/// The offset rest - world at each voxel's closest point on the surface:
/// beyond the particles, where there are no rest positions, the noise moves
/// with the surface and still varies along its normals.
openvdb::Vec3SGrid::Ptr offsetsFromSurface(const openvdb::Vec3SGrid& closest, const openvdb::Vec3SGrid& rest)
{
    const double voxel = closest.voxelSize()[0]; // the transform is a pure scale, as the splat's
    openvdb::Vec3SGrid::Ptr offsets = openvdb::Vec3SGrid::create();
    offsets->setTransform(closest.transform().copy());
    offsets->tree().topologyUnion(closest.tree());
    openvdb::tree::LeafManager<openvdb::Vec3STree>(offsets->tree())
        .foreach ([&](openvdb::Vec3STree::LeafNodeType& leaf, std::size_t) {
            const auto closestAt = closest.getConstAccessor();
            TrilinearSampler<openvdb::Vec3STree> restAt(rest.tree());
            for (auto v = leaf.beginValueOn(); v; ++v) {
                const openvdb::Vec3d point(closestAt.getValue(v.getCoord()));
                v.setValue(openvdb::Vec3s(openvdb::Vec3d(restAt.atIndex(point)) - point * voxel));
            }
        });
    return offsets;
}

/// The mean of billow noise (twice the mean |noise| of Perlin's improved
/// noise, measured over 216,000 points; the same for any octaves, as billow
/// normalizes its sum): a displaced surface moves out by as much as in.
constexpr double kMeanBillow = 0.44;

/// A displaced surface's octaves split in two: the coarse ones (at least
/// four of the splat's voxels a lattice cell) move it on the splat's grid,
/// the fine ones on the detail's, each part over its share of the range.
struct OctaveSplit {
    int coarseOctaves = 0;
    double coarseRange = 0.0, fineRange = 0.0; ///< world units
    FractalOptions coarse, fine;               ///< fine: its octave 0 is octave coarseOctaves
    double fineFrequencyScale = 1.0;           ///< 2^coarseOctaves

    OctaveSplit(const VolumeDetail& detail, double coarseVoxel)
    {
        double weight = 1.0, coarseSum = 0.0, sum = 0.0;
        for (int octave = 0; octave < detail.octaves; ++octave, weight *= detail.gain) {
            if (detail.frequency * std::ldexp(1.0, octave) * coarseVoxel <= 0.25) {
                coarseOctaves = octave + 1;
                coarseSum += weight;
            }
            sum += weight;
        }
        coarseRange = detail.displacementRange() * coarseSum / sum;
        fineRange = detail.displacementRange() - coarseRange;
        coarse = {coarseOctaves, 2.0, detail.gain};
        fine = {detail.octaves - coarseOctaves, 2.0, detail.gain};
        fineFrequencyScale = std::ldexp(1.0, coarseOctaves);
    }
};

/// Displacements b - 0.44 of a batch of points, each blended over the rest
/// channels: their billow sums drawn together (noise.h), as a point's few
/// octaves in each channel alone leave SIMD lanes idle (three octaves in two
/// channels: eight lanes' work for six values). The main job's detail stage
/// at frames 100-129: 0.43 -> 0.36 s a frame, the same grids bit for bit.
class BlendedBillows {
public:
    BlendedBillows(const GradientNoise& noise, const FractalOptions& octaves, const std::vector<RestChannel>& channels,
                   float frequency, float scale, double inverseNorm)
        : mNoise(noise), mOctaves(octaves), mChannels(channels), mFrequency(frequency), mScale(scale), mInverseNorm(inverseNorm),
          mCapacity(std::size_t(std::max(1, kMaxBatchOctaves / std::max(1, octaves.octaves * int(channels.size())))))
    {
        mQueries.reserve(mCapacity * channels.size());
        mSums.resize(mQueries.capacity());
        mDisplacements.resize(mCapacity);
    }

    /// Adds a point, by its rest position in channel r: restOf(r), world units.
    template<typename RestOf>
    void add(const RestOf& restOf)
    {
        for (std::size_t r = 0; r < mChannels.size(); ++r)
            mQueries.push_back({(restOf(r) * mFrequency + mChannels[r].noiseOffset) * mScale, mOctaves});
    }
    bool full() const { return mQueries.size() == mCapacity * mChannels.size(); }

    /// The displacements of the points added since the last call, in their
    /// order; none are left.
    const double* take()
    {
        const std::size_t points = mQueries.size() / std::max<std::size_t>(1, mChannels.size());
        if (mOctaves.octaves > 0 && points > 0) billow(mNoise, mQueries.data(), mQueries.size(), mSums.data());
        for (std::size_t point = 0; point < points; ++point) {
            float b = 0.0f;
            if (mOctaves.octaves > 0)
                for (std::size_t r = 0; r < mChannels.size(); ++r)
                    b += mChannels[r].weight * (mSums[point * mChannels.size() + r] - float(kMeanBillow));
            mDisplacements[point] = double(b) * mInverseNorm;
        }
        mQueries.clear();
        return mDisplacements.data();
    }

private:
    const GradientNoise& mNoise;
    FractalOptions mOctaves;
    const std::vector<RestChannel>& mChannels;
    float mFrequency, mScale;
    double mInverseNorm;
    std::size_t mCapacity; ///< points
    std::vector<FbmQuery> mQueries;
    std::vector<float> mSums;
    std::vector<double> mDisplacements;
};

/// DetailStyle::Displaced: the splat's surface, where its density is
/// edgeSoftness / 2, moved along its normal by billow noise: its coarse
/// octaves on the splat's grid, its fine ones on the detail's grid, only
/// within their own (smaller) range of the surface the coarse ones moved.
/// A single sum of all the octaves on the detail's grid visited every fine
/// voxel within the whole range of the splat's surface, each drawing every
/// octave, and took 3.6 times as long (BM_DetailStage, with the fine
/// voxels' reads made once per coarse voxel too).
openvdb::FloatGrid::Ptr displacedDensity(const openvdb::FloatGrid& density, const std::vector<openvdb::Vec3SGrid::Ptr>& rests,
                                         const std::vector<RestChannel>& channels, const VolumeDetail& detail,
                                         double edgeSoftness)
{
    const float surfaceDensity = float(0.5 * edgeSoftness);
    // A cloud nowhere that dense has no surface to move: it stays as it is.
    if (!(openvdb::tools::minMax(density.tree()).max() > surfaceDensity)) return density.deepCopy();

    const double coarse = density.voxelSize()[0];
    const int ratio = fineRatio(density, detail.voxelSize);
    const double fine = coarse / ratio;
    const OctaveSplit split(detail, coarse);
    // How far each part moves the surface out and in: b - 0.44 for b in [0, 1].
    const double coarseOutward = split.coarseRange * (1.0 - kMeanBillow);
    const double fineOutward = split.fineRange * (1.0 - kMeanBillow), fineInward = split.fineRange * kMeanBillow;

    // The signed distance to the splat's surface over every coarse voxel
    // the moved surface can reach, and the rest positions' offsets there.
    // Two coarse voxels more each way: the fine voxels that draw noise read
    // the coarse ones around them. Deeper, the density stays inside whatever
    // the octaves; farther out, it is empty.
    const double inward = split.coarseRange * kMeanBillow + fineInward + fine + 2.0 * coarse;
    const double outward = coarseOutward + fineOutward + fine + 2.0 * coarse;
    SurfaceDistance surface(density, surfaceDensity, inward, outward);
    std::vector<openvdb::Vec3SGrid::Ptr> offsets;
    for (const auto& rest : rests) offsets.push_back(offsetsFromSurface(*surface.closest, *rest));

    const GradientNoise noise(detail.seed);
    const float frequency = float(detail.frequency);
    const double inverseNorm = inverseBlendNorm(channels);

    // The coarse octaves move the surface on the splat's grid, their
    // displacement read trilinearly between its voxels: the signed distance
    // less it is zero on the surface they moved, and the fine octaves move
    // that surface in turn, as one sum of all the octaves would. Its
    // background: as far outside as the splat's distance's.
    const openvdb::FloatGrid::Ptr movedDistance = surface.distance; // moved in place
    openvdb::tree::LeafManager<openvdb::FloatTree>(movedDistance->tree())
        .foreach ([&](openvdb::FloatTree::LeafNodeType& leaf, std::size_t) {
            std::vector<openvdb::Vec3SGrid::ConstAccessor> offsetAt;
            for (const auto& offset : offsets) offsetAt.push_back(offset->getConstAccessor());
            // Beyond the band, where there is no closest point, the density
            // is inside or empty whatever the octaves.
            const openvdb::Vec3STree::LeafNodeType* closestLeaf = surface.closest->tree().probeConstLeaf(leaf.origin());
            if (!closestLeaf) return;
            BlendedBillows billows(noise, split.coarse, channels, frequency, 1.0f, inverseNorm);
            std::vector<openvdb::Index> moved; // the voxels whose displacement billows holds
            const auto move = [&] {
                const double* displacements = billows.take();
                for (std::size_t n = 0; n < moved.size(); ++n)
                    leaf.setValueOnly(moved[n], float(double(leaf.getValue(moved[n])) - split.coarseRange * displacements[n]));
                moved.clear();
            };
            for (auto voxel = leaf.cbeginValueOn(); voxel; ++voxel) {
                if (!closestLeaf->isValueOn(voxel.pos())) continue;
                const openvdb::Coord c = voxel.getCoord();
                const openvdb::Vec3d world = openvdb::Vec3d(c.x(), c.y(), c.z()) * coarse; // the transform is a pure scale
                billows.add([&](std::size_t r) { return openvdb::Vec3f(world + openvdb::Vec3d(offsetAt[r].getValue(c))); });
                moved.push_back(voxel.pos());
                if (billows.full()) move();
            }
            move();
        });
    // The fine octaves, on the detail's grid, within their range of that
    // surface: only in the coarse voxels that have a voxel within that range
    // among their 3 x 3 x 3 (each fine voxel reads the 2 x 2 x 2 coarse ones
    // around it). The others' blocks are empty, most of the voxels the
    // moved surface could reach: reading their neighbourhoods to find so
    // took 0.6 of the stirred bank's 3.0 s at frame 120.
    const double farthestLump = fineOutward + fine;
    const openvdb::MaskGrid::Ptr nearSurface = topologyOf(*movedDistance);
    openvdb::tree::LeafManager<openvdb::MaskTree>(nearSurface->tree())
        .foreach ([&](openvdb::MaskTree::LeafNodeType& leaf, std::size_t) {
            const openvdb::FloatTree::LeafNodeType& distances = *movedDistance->tree().probeConstLeaf(leaf.origin());
            for (auto v = leaf.beginValueOn(); v; ++v)
                if (double(distances.getValue(v.pos())) > farthestLump) leaf.setValueOff(v.pos());
        });
    openvdb::tools::dilateActiveValues(nearSurface->tree(), 1, openvdb::tools::NN_FACE_EDGE_VERTEX, openvdb::tools::IGNORE_TILES);
    nearSurface->tree().topologyIntersection(movedDistance->tree());
    const FineTaps taps(ratio);
    const float fineScale = float(split.fineFrequencyScale);
    struct OffsetNeighbourhood {
        openvdb::Vec3s n[3][3][3];
    };
    return resampleFiner(density, *nearSurface, ratio, [&] {
        std::vector<LeafHalo<openvdb::Vec3STree>> offsetAt;
        for (const auto& offset : offsets) offsetAt.emplace_back(offset->tree());
        // A fine voxel near the surface, waiting for its displacement.
        struct Displaced {
            double* value;
            double distance, inside;
        };
        return [&, densityAt = LeafHalo<openvdb::FloatTree>(density.tree()),
                distanceAt = LeafHalo<openvdb::FloatTree>(movedDistance->tree()), offsetAt = std::move(offsetAt),
                offsetNeighbourhoods = std::vector<OffsetNeighbourhood>(offsets.size()),
                billows = BlendedBillows(noise, split.fine, channels, frequency, fineScale, inverseNorm),
                displaced = std::vector<Displaced>()](const openvdb::Coord& c, double* values) mutable {
            // Each fine voxel reads the 2x2x2 coarse voxels around it: all
            // of them lie in this neighbourhood, and its distance below the
            // neighbourhood's greatest.
            float d[3][3][3];
            distanceAt.neighbourhood(c, d);
            const float greatest = *std::max_element(&d[0][0][0], &d[0][0][0] + 27);
            float rho[3][3][3];
            densityAt.neighbourhood(c, rho);
            // Inside, at least the surface's density doubled: a lump of the
            // finest octave is a fine voxel or two across and must still show.
            const auto insideAt = [&](int i, int j, int k) { return std::max(double(taps.at(rho, i, j, k)), edgeSoftness); };
            if (greatest < -fineInward - fine) { // below the deepest fine crease
                for (int i = 0; i < ratio; ++i)
                    for (int j = 0; j < ratio; ++j)
                        for (int k = 0; k < ratio; ++k) *values++ = insideAt(i, j, k);
                return;
            }
            for (std::size_t r = 0; r < offsets.size(); ++r) offsetAt[r].neighbourhood(c, offsetNeighbourhoods[r].n);
            const auto displace = [&] {
                const double* displacements = billows.take();
                for (std::size_t n = 0; n < displaced.size(); ++n) {
                    const double h = split.fineRange * displacements[n];
                    *displaced[n].value = displaced[n].inside * smoothstep01(0.5 - (displaced[n].distance - h) / fine);
                }
                displaced.clear();
            };
            for (int i = 0; i < ratio; ++i)
                for (int j = 0; j < ratio; ++j)
                    for (int k = 0; k < ratio; ++k) {
                        const double distanceHere = taps.at(d, i, j, k);
                        double& value = *values++;
                        if (distanceHere > farthestLump) {
                            value = 0.0;
                            continue;
                        }
                        const double inside = insideAt(i, j, k);
                        if (distanceHere < -fineInward - fine) {
                            value = inside;
                            continue;
                        }
                        const openvdb::Vec3d world = (openvdb::Vec3d(c.x(), c.y(), c.z()) +
                                                      openvdb::Vec3d(taps.offset(i), taps.offset(j), taps.offset(k))) *
                                                     coarse;
                        billows.add([&](std::size_t r) {
                            return openvdb::Vec3f(world + openvdb::Vec3d(taps.at(offsetNeighbourhoods[r].n, i, j, k)));
                        });
                        displaced.push_back({&value, distanceHere, inside});
                        if (billows.full()) displace();
                    }
            displace();
        };
    });
}

} // namespace

namespace {

/// Deactivates every voxel below threshold, its value set to the background
/// (so that files need not store it), and prunes the leaves left empty.
void leaveOutBelow(openvdb::FloatGrid& grid, float threshold)
{
    // The voxels on the faces of the active box stay, so that the grid keeps
    // its bounds: what is placed by them (a renderer's light lattice, a
    // host's bounding box) does not move.
    const openvdb::CoordBBox bounds = grid.evalActiveVoxelBoundingBox();
    const auto onFace = [&bounds](const openvdb::Coord& c) {
        for (int axis = 0; axis < 3; ++axis)
            if (c[axis] == bounds.min()[axis] || c[axis] == bounds.max()[axis]) return true;
        return false;
    };
    openvdb::tree::LeafManager<openvdb::FloatTree> leaves(grid.tree());
    leaves.foreach ([&](openvdb::FloatTree::LeafNodeType& leaf, std::size_t) {
        for (auto it = leaf.beginValueOn(); it; ++it)
            if (*it < threshold && !onFace(it.getCoord())) leaf.setValueOff(it.pos(), 0.0f);
    });
    openvdb::tools::pruneInactive(grid.tree());
}

/// Leaves out the velocities where there is no density (of no use to a
/// host), their values the background so that they cost no bytes. The
/// density may be finer than the velocity (its detail): a velocity voxel is
/// kept when any density voxel it overlaps is.
void keepWhereActive(openvdb::Vec3SGrid& velocity, const openvdb::FloatGrid& density)
{
    openvdb::tree::LeafManager<openvdb::Vec3STree> leaves(velocity.tree());
    leaves.foreach ([&](openvdb::Vec3STree::LeafNodeType& leaf, std::size_t) {
        const auto kept = density.getConstAccessor();
        for (auto it = leaf.beginValueOn(); it; ++it) {
            const openvdb::Vec3d centre = it.getCoord().asVec3d();
            const openvdb::Vec3d lo = density.worldToIndex(velocity.indexToWorld(centre - 0.5)),
                                 hi = density.worldToIndex(velocity.indexToWorld(centre + 0.5));
            // Density voxels whose centres lie within the velocity voxel.
            const openvdb::CoordBBox overlap(openvdb::Coord::ceil(lo - 0.5 + 1e-6), openvdb::Coord::floor(hi + 0.5 - 1e-6));
            bool any = false;
            for (auto c = overlap.begin(); c && !any; ++c) any = kept.isValueOn(*c);
            if (!any) leaf.setValueOff(it.pos(), openvdb::Vec3s(0.0f));
        }
    });
    openvdb::tools::pruneInactive(velocity.tree());
}

} // namespace

float Condensation::share(float y, float peak) const
{
    return enabled() ? float(smoothstep01(1.0 - (double(peak) - double(y)) / depth)) : 1.0f;
}

DensityGrids splatParticles(const ParticleSet& particles, const VolumeOptions& options, SplatSeconds* seconds)
{
    const Stopwatch watch;
    double meanRadius = 0.0;
    for (const float r : particles.radius) meanRadius += r;
    meanRadius = particles.size() > 0 ? meanRadius / double(particles.size()) : 1.0;
    const VolumeOptions resolved = options.resolved(meanRadius);
    resolved.validate();
    const double voxel = resolved.voxelSize;
    const int passes = blurPasses(resolved.kernelRadius / voxel);
    const double perWeight = resolved.densityPerParticle / (voxel * voxel * voxel); // density of a unit weight
    // The rest positions the detail is drawn at, those with a weight.
    std::vector<RestChannel> channels;
    if (resolved.detail.enabled()) {
        const bool dual = particles.rest2.size() == particles.size();
        const float weight2 = dual ? std::clamp(particles.rest2Weight, 0.0f, 1.0f) : 0.0f;
        if (weight2 < 1.0f)
            channels.push_back(
                {particles.rest.size() == particles.size() ? &particles.rest : &particles.position, 1.0f - weight2});
        if (weight2 > 0.0f) channels.push_back({&particles.rest2, weight2, openvdb::Vec3f(131.7f, -71.3f, 217.9f)});
    }

    const auto transform = openvdb::math::Transform::createLinearTransform(voxel);
    const Condensation& condensation = resolved.condensation;

    // Index space is world space over the voxel size (the transform is a pure scale).
    const double inverseVoxel = 1.0 / voxel;
    const auto indexOf = [&](std::size_t p) { return openvdb::Vec3d(Vec3d(particles.position[p]) * inverseVoxel); };

    // A run of particles is deposited with their trilinear weights
    // (cloud-in-cell: the eight voxels around each) into dense arrays over
    // their box, then the voxels they reached are added to the chunk's grids.
    // Each voxel's sum runs over the particles in order, so the sums are those
    // of voxel-by-voxel accumulation.
    const auto splatRun = [&](std::size_t first, std::size_t last, const openvdb::CoordBBox& box, DenseSums& sums, Splat& into) {
        sums.reset(box, channels.size());
        for (std::size_t p = first; p != last; ++p) {
            const openvdb::Vec3s v = particles.velocity[p];
            const float y = particles.position[p].y();
            const float share = condensation.share(y, particles.peak.size() == particles.size() ? particles.peak[p] : y);
            if (share == 0.0f) continue;
            const openvdb::Vec3d index = indexOf(p);
            const openvdb::Coord base = openvdb::Coord::floor(index);
            const float fx = float(index.x() - base.x()), fy = float(index.y() - base.y()), fz = float(index.z() - base.z());
            const float wx[2] = {1.0f - fx, fx}, wy[2] = {1.0f - fy, fy}, wz[2] = {1.0f - fz, fz};
            for (int i = 0; i < 2; ++i)
                for (int j = 0; j < 2; ++j) {
                    const std::size_t row = sums.at(base.offsetBy(i, j, 0));
                    for (int k = 0; k < 2; ++k) {
                        const float weight = wx[i] * wy[j] * wz[k] * share;
                        const std::size_t at = row + std::size_t(k);
                        sums.w[at] += weight;
                        sums.vx[at] += v[0] * weight;
                        sums.vy[at] += v[1] * weight;
                        sums.vz[at] += v[2] * weight;
                        for (std::size_t c = 0; c < channels.size(); ++c) {
                            const Vec3f& r = (*channels[c].positions)[p];
                            for (int axis = 0; axis < 3; ++axis) sums.r[c][axis][at] += r[axis] * weight;
                        }
                    }
                }
        }
        auto weightAccessor = into.weight->getAccessor();
        auto momentumAccessor = into.momentum->getAccessor();
        std::vector<openvdb::Vec3SGrid::Accessor> restAccessors;
        for (std::size_t c = 0; c < channels.size(); ++c) restAccessors.push_back(into.rest[c]->getAccessor());
        for (auto c = box.begin(); c; ++c) {
            const std::size_t at = sums.at(*c);
            if (sums.w[at] == 0.0f) continue;
            weightAccessor.setValueOn(*c, weightAccessor.getValue(*c) + sums.w[at]);
            momentumAccessor.setValueOn(*c,
                                        momentumAccessor.getValue(*c) + openvdb::Vec3s(sums.vx[at], sums.vy[at], sums.vz[at]));
            for (std::size_t r = 0; r < channels.size(); ++r) {
                const auto& sum = sums.r[r];
                restAccessors[r].setValueOn(*c,
                                            restAccessors[r].getValue(*c) + openvdb::Vec3s(sum[0][at], sum[1][at], sum[2][at]));
            }
        }
    };

    Splat total = tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, particles.size(), kParticlesPerChunk), Splat(transform),
        [&](const tbb::blocked_range<std::size_t>& range, const Splat&) {
            Splat partial(transform); // its own grids: the identity's are shared by every chunk
            DenseSums sums;
            // Runs of consecutive particles whose box stays small next to
            // their number: the simulator keeps particles in about spatial
            // order (ParticleSet::sortSpatially every few frames), so runs are
            // long where the cloud is dense; in random order they are short,
            // and the splat about ten times slower.
            const auto reached = [&](std::size_t p) { // the eight voxels a particle deposits into
                const openvdb::Coord corner = openvdb::Coord::floor(indexOf(p));
                return openvdb::CoordBBox(corner, corner + openvdb::Coord(1));
            };
            for (std::size_t first = range.begin(); first != range.end();) {
                openvdb::CoordBBox box = reached(first);
                std::size_t last = first + 1;
                for (; last != range.end(); ++last) {
                    openvdb::CoordBBox grown = box;
                    grown.expand(reached(last));
                    if (grown.volume() > std::max<uint64_t>(kRunVoxels, kRunVoxelsPerParticle * (last - first + 1))) break;
                    box = grown;
                }
                splatRun(first, last, box, sums, partial);
                first = last;
            }
            return partial;
        },
        [](Splat a, const Splat& b) { // b is discarded after the join: its leaves are taken
            addLeaves(a.weight->tree(), b.weight->tree());
            addLeaves(a.momentum->tree(), b.momentum->tree());
            for (std::size_t r = 0; r < kMaxRests; ++r) addLeaves(a.rest[r]->tree(), b.rest[r]->tree());
            return a;
        },
        tbb::simple_partitioner());

    // The sums blurred: the kernel is the trilinear weights blurred, and the
    // means (velocity, rest) are of the blurred weights.
    blur(*total.weight, passes);
    blur(*total.momentum, passes);
    for (std::size_t r = 0; r < channels.size(); ++r) blur(*total.rest[r], passes);

    DensityGrids grids;
    grids.density = openvdb::FloatGrid::create(0.0f);
    grids.density->setTransform(transform->copy());
    grids.velocity = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    grids.velocity->setTransform(transform->copy());
    // The mean rest positions: the rest sums over the weights, in place.
    std::vector<openvdb::Vec3SGrid::Ptr> restMeans(total.rest.begin(), total.rest.begin() + channels.size());
    for (const auto& rest : restMeans) {
        const auto weight = total.weight->getConstAccessor();
        for (auto it = rest->beginValueOn(); it; ++it) {
            const float w = weight.getValue(it.getCoord());
            it.setValue(w > 0.0f ? *it / w : openvdb::Vec3s(0.0f));
        }
    }

    auto density = grids.density->getAccessor();
    auto velocity = grids.velocity->getAccessor();
    auto momentum = total.momentum->getConstAccessor();
    for (auto it = total.weight->cbeginValueOn(); it; ++it) {
        const float w = *it;
        if (!(w > 0.0f)) continue;
        density.setValue(it.getCoord(), float(perWeight * w));
        velocity.setValue(it.getCoord(), momentum.getValue(it.getCoord()) / w);
    }
    // The peak density of one lone particle: the scale of the edges and of the cutoff.
    const double lonePeak = perWeight * std::pow(centreWeight(passes), 3);
    const double splatDone = watch.seconds();
    if (!channels.empty()) {
        const double softness = resolved.detail.edgeSoftness > 0.0 ? resolved.detail.edgeSoftness : lonePeak;
        grids.density = resolved.detail.style == DetailStyle::Displaced
                            ? displacedDensity(*grids.density, restMeans, channels, resolved.detail, softness)
                            : detailedDensity(*grids.density, restMeans, channels, resolved.detail, softness);
    }
    if (resolved.cutoff > 0.0) {
        leaveOutBelow(*grids.density, float(resolved.cutoff * lonePeak));
        keepWhereActive(*grids.velocity, *grids.density);
    }
    grids.density->setName("density");
    grids.density->setGridClass(openvdb::GRID_FOG_VOLUME);
    grids.velocity->setName("vel");
    grids.velocity->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    grids.density->setSaveFloatAsHalf(options.densityPrecision == GridPrecision::Half);
    grids.velocity->setSaveFloatAsHalf(options.velocityPrecision == GridPrecision::Half);
    if (seconds) *seconds = {splatDone, watch.seconds() - splatDone};
    return grids;
}

} // namespace vfield
