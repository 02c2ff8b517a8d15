#include <vfield/volume/density_splat.h>

#include "detail_styles.h"

#include <vfield/core/field_visitors.h>
#include <vfield/core/stopwatch.h>

#include <openvdb/tools/Filter.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace vfield {

void VolumeSettings::validate() const
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

VolumeSettings VolumeSettings::resolved(double meanParticleRadius) const
{
    VolumeSettings r = *this;
    if (r.voxelSize == 0.0) r.voxelSize = meanParticleRadius;
    r.kernelRadius = std::max(r.kernelRadius > 0.0 ? r.kernelRadius : 2.0 * meanParticleRadius, r.voxelSize);
    return r;
}

namespace {

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

DensityGrids splatParticles(const ParticleSet& particles, const VolumeSettings& options, SplatSeconds* seconds)
{
    const Stopwatch watch;
    double meanRadius = 0.0;
    for (const float r : particles.radius) meanRadius += r;
    meanRadius = particles.size() > 0 ? meanRadius / double(particles.size()) : 1.0;
    const VolumeSettings resolved = options.resolved(meanRadius);
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
    const CondensationSettings& condensation = resolved.condensation;

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
