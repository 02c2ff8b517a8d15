#include "deposit.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

namespace vfield {

namespace {

/// The channels a particle deposits: W, W v (three), and W rest (three a rest channel).
constexpr std::size_t kMaxChannels = 4 + 3 * kMaxRests;
using FloatLeaf = openvdb::FloatTree::LeafNodeType;
using Vec3Leaf = openvdb::Vec3STree::LeafNodeType;
constexpr int kLeafDim = int(FloatLeaf::DIM);
constexpr std::size_t kLeafVoxels = FloatLeaf::SIZE;

/// Particles a task deposits at least.
constexpr std::size_t kParticlesPerTask = 16384;
/// A run of particles deposited into one dense box grows while the box holds
/// at most this many voxels, or this many per particle: the box's zeroing and
/// transfer stay small next to the deposit.
constexpr uint64_t kRunVoxels = 4096, kRunVoxelsPerParticle = 16;

/// Numbers as integer multiples of 2^-e, held in doubles: integers sum to
/// the same value in any order (up to 2^53), where floating-point sums differ
/// in their last bits, which the detail's thresholds can turn into visible
/// differences.
class FixedPoint {
public:
    /// The finest one, down to 2^-40, in which `count` values of magnitude
    /// at most `largest` sum to at most 2^51 units: each rounds as below, and
    /// every sum is exact.
    static FixedPoint forSums(double largest, std::size_t count)
    {
        const double bound = std::max(largest, 1e-300) * double(std::max<std::size_t>(count, 1));
        return FixedPoint(std::min(40, int(std::floor(51.0 - std::log2(bound)))));
    }
    FixedPoint() : FixedPoint(0) {}
    /// x in units of 2^-e, rounded to the nearest integer: adding and taking
    /// away 1.5 x 2^52 leaves no bits below the units' for |x| up to 2^51
    /// units (one rounding, as nearbyint, without its call).
    double operator()(double x) const { return (x * mScale + kRound) - kRound; }
    double value(double units) const { return units * mUnit; }

private:
    static constexpr double kRound = 6755399441055744.0; // 1.5 x 2^52
    explicit FixedPoint(int exponent) : mScale(std::ldexp(1.0, exponent)), mUnit(std::ldexp(1.0, -exponent)) {}
    double mScale, mUnit;
};

/// The largest magnitude of any component of the values.
double largestComponent(const std::vector<Vec3f>& values)
{
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, values.size(), kParticlesPerTask), 0.0,
        [&](const tbb::blocked_range<std::size_t>& range, double largest) {
            for (std::size_t p = range.begin(); p != range.end(); ++p)
                for (int axis = 0; axis < 3; ++axis) largest = std::max(largest, double(std::abs(values[p][axis])));
            return largest;
        },
        [](double a, double b) { return std::max(a, b); });
}

/// What the particles deposit, channel by channel: channel 0 the weight W,
/// 1 to 3 W v, then W rest for each rest channel; and each channel's fixed point.
struct Channels {
    std::size_t count = 0;
    std::array<FixedPoint, kMaxChannels> fixed;

    Channels(const ParticleSet& particles, const std::vector<RestChannel>& rests) : count(4 + 3 * rests.size())
    {
        const std::size_t n = particles.size();
        fixed[0] = FixedPoint::forSums(1.0, n); // a weight is at most 1
        const FixedPoint velocity = FixedPoint::forSums(largestComponent(particles.velocity), n);
        std::fill_n(fixed.begin() + 1, 3, velocity);
        for (std::size_t r = 0; r < rests.size(); ++r)
            std::fill_n(fixed.begin() + 4 + 3 * std::ptrdiff_t(r), 3,
                        FixedPoint::forSums(largestComponent(*rests[r].positions), n));
    }
};

/// Sums over the box a run of particles deposits into, one array per channel
/// so that the innermost loop (along z) is plain arithmetic.
struct DenseSums {
    openvdb::Coord origin, dim;
    std::array<std::vector<double>, kMaxChannels> channel;

    /// Zeroes the first `channels` over a new box, keeping the arrays' memory.
    void reset(const openvdb::CoordBBox& box, std::size_t channels)
    {
        origin = box.min();
        dim = box.dim();
        const std::size_t n = std::size_t(dim.x()) * std::size_t(dim.y()) * std::size_t(dim.z());
        for (std::size_t c = 0; c < channels; ++c) channel[c].assign(n, 0.0);
    }
    std::size_t at(const openvdb::Coord& c) const
    {
        return (std::size_t(c.x() - origin.x()) * std::size_t(dim.y()) + std::size_t(c.y() - origin.y())) * std::size_t(dim.z()) +
               std::size_t(c.z() - origin.z());
    }
};

/// The sums of one leaf's voxels, integers in their channels' units:
/// channel c of voxel n at [c * kLeafVoxels + n].
using LeafSums = std::vector<double>;
using LeafMap = std::unordered_map<openvdb::Coord, LeafSums>;

/// Adds a run's box of sums into the leaves it overlaps.
void addToLeaves(const DenseSums& sums, const openvdb::CoordBBox& box, std::size_t channels, LeafMap& leaves)
{
    const openvdb::Coord first = box.min() & ~(kLeafDim - 1), last = box.max() & ~(kLeafDim - 1);
    for (int lx = first.x(); lx <= last.x(); lx += kLeafDim)
        for (int ly = first.y(); ly <= last.y(); ly += kLeafDim)
            for (int lz = first.z(); lz <= last.z(); lz += kLeafDim) {
                const openvdb::Coord origin(lx, ly, lz);
                const openvdb::Coord lo = openvdb::Coord::maxComponent(origin, box.min()),
                                     hi = openvdb::Coord::minComponent(origin.offsetBy(kLeafDim - 1), box.max());
                LeafSums* leaf = nullptr;
                for (int x = lo.x(); x <= hi.x(); ++x)
                    for (int y = lo.y(); y <= hi.y(); ++y)
                        for (int z = lo.z(); z <= hi.z(); ++z) {
                            const openvdb::Coord c(x, y, z);
                            const std::size_t at = sums.at(c);
                            bool any = false;
                            for (std::size_t ch = 0; ch < channels && !any; ++ch) any = sums.channel[ch][at] != 0.0;
                            if (!any) continue;
                            if (!leaf) {
                                leaf = &leaves[origin];
                                if (leaf->empty()) leaf->assign(channels * kLeafVoxels, 0.0);
                            }
                            const std::size_t n = FloatLeaf::coordToOffset(c);
                            for (std::size_t ch = 0; ch < channels; ++ch) (*leaf)[ch * kLeafVoxels + n] += sums.channel[ch][at];
                        }
            }
}

/// Deposits particles first..last, whose deposit lies in box, into the sums.
void depositRun(const ParticleSet& particles, const std::vector<RestChannel>& rests, const Channels& channels,
                const CondensationSettings& condensation, double inverseVoxel, std::size_t first, std::size_t last,
                DenseSums& sums)
{
    const bool hasPeaks = particles.peak.size() == particles.size(), hasOrigins = particles.origin.size() == particles.size(),
               hasFades = particles.fade.size() == particles.size();
    std::array<double, kMaxChannels> source{1.0};
    for (std::size_t p = first; p != last; ++p) {
        const float y = particles.position[p].y();
        float share = condensation.share(y, hasPeaks ? particles.peak[p] : y, hasOrigins ? particles.origin[p] : y);
        if (hasFades) share *= particles.fade[p];
        if (share == 0.0f) continue;
        for (int axis = 0; axis < 3; ++axis) source[std::size_t(1 + axis)] = double(particles.velocity[p][axis]);
        for (std::size_t r = 0; r < rests.size(); ++r)
            for (int axis = 0; axis < 3; ++axis) source[4 + 3 * r + std::size_t(axis)] = double((*rests[r].positions)[p][axis]);
        const openvdb::Vec3d index = openvdb::Vec3d(Vec3d(particles.position[p]) * inverseVoxel);
        const openvdb::Coord base = openvdb::Coord::floor(index);
        const float fx = float(index.x() - base.x()), fy = float(index.y() - base.y()), fz = float(index.z() - base.z());
        const float wx[2] = {1.0f - fx, fx}, wy[2] = {1.0f - fy, fy}, wz[2] = {1.0f - fz, fz};
        for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j) {
                const std::size_t row = sums.at(base.offsetBy(i, j, 0));
                for (int k = 0; k < 2; ++k) {
                    const double weight = double(wx[i] * wy[j] * wz[k] * share);
                    const std::size_t at = row + std::size_t(k);
                    for (std::size_t c = 0; c < channels.count; ++c) sums.channel[c][at] += channels.fixed[c](weight * source[c]);
                }
            }
    }
}

/// The leaves' sums as float grids, a voxel on where its weight is above 0.
Deposit toGrids(const LeafMap& leaves, const Channels& channels, std::size_t rests,
                const openvdb::math::Transform::Ptr& transform)
{
    struct Leaves {
        FloatLeaf* weight = nullptr;
        Vec3Leaf* momentum = nullptr;
        std::array<Vec3Leaf*, kMaxRests> rest{};
    };
    std::vector<const std::pair<const openvdb::Coord, LeafSums>*> sums;
    for (const auto& leaf : leaves) sums.push_back(&leaf);
    std::vector<Leaves> made(sums.size());
    tbb::parallel_for(std::size_t(0), sums.size(), [&](std::size_t i) {
        const openvdb::Coord& origin = sums[i]->first;
        const LeafSums& values = sums[i]->second;
        Leaves& out = made[i];
        const auto vectorOf = [&](std::size_t channel, std::size_t n) {
            return openvdb::Vec3s(float(channels.fixed[channel].value(values[channel * kLeafVoxels + n])),
                                  float(channels.fixed[channel + 1].value(values[(channel + 1) * kLeafVoxels + n])),
                                  float(channels.fixed[channel + 2].value(values[(channel + 2) * kLeafVoxels + n])));
        };
        for (std::size_t n = 0; n < kLeafVoxels; ++n) {
            if (values[n] <= 0.0) continue;
            if (!out.weight) {
                out.weight = new FloatLeaf(origin, 0.0f, false);
                out.momentum = new Vec3Leaf(origin, openvdb::Vec3s(0.0f), false);
                for (std::size_t r = 0; r < rests; ++r) out.rest[r] = new Vec3Leaf(origin, openvdb::Vec3s(0.0f), false);
            }
            const auto offset = openvdb::Index(n);
            out.weight->setValueOn(offset, float(channels.fixed[0].value(values[n])));
            out.momentum->setValueOn(offset, vectorOf(1, n));
            for (std::size_t r = 0; r < rests; ++r) out.rest[r]->setValueOn(offset, vectorOf(4 + 3 * r, n));
        }
    });
    Deposit deposit;
    deposit.weight = openvdb::FloatGrid::create(0.0f);
    deposit.weight->setTransform(transform);
    deposit.momentum = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    deposit.momentum->setTransform(transform);
    for (std::size_t r = 0; r < rests; ++r) {
        deposit.rests.push_back(openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f)));
        deposit.rests.back()->setTransform(transform);
    }
    for (const Leaves& leaf : made) {
        if (!leaf.weight) continue;
        deposit.weight->tree().addLeaf(leaf.weight);
        deposit.momentum->tree().addLeaf(leaf.momentum);
        for (std::size_t r = 0; r < rests; ++r) deposit.rests[r]->tree().addLeaf(leaf.rest[r]);
    }
    return deposit;
}

} // namespace

Deposit depositParticles(const ParticleSet& particles, const std::vector<RestChannel>& rests,
                         const CondensationSettings& condensation, const openvdb::math::Transform::Ptr& transform)
{
    const Channels channels(particles, rests);
    // The transform is a pure scale: index space is world space over the voxel size.
    const double inverseVoxel = 1.0 / transform->voxelSize()[0];
    const auto reached = [&](std::size_t p) { // the eight voxels a particle deposits into
        const openvdb::Coord corner = openvdb::Coord::floor(openvdb::Vec3d(Vec3d(particles.position[p]) * inverseVoxel));
        return openvdb::CoordBBox(corner, corner + openvdb::Coord(1));
    };
    tbb::enumerable_thread_specific<LeafMap> threadLeaves;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, particles.size(), kParticlesPerTask),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          LeafMap& leaves = threadLeaves.local();
                          DenseSums sums;
                          // Runs of consecutive particles whose box stays small next to
                          // their number: long where the cloud is dense and its particles
                          // in spatial order, short in random order.
                          for (std::size_t first = range.begin(); first != range.end();) {
                              openvdb::CoordBBox box = reached(first);
                              std::size_t last = first + 1;
                              for (; last != range.end(); ++last) {
                                  openvdb::CoordBBox grown = box;
                                  grown.expand(reached(last));
                                  const uint64_t limit =
                                      std::max<uint64_t>(kRunVoxels, kRunVoxelsPerParticle * (last - first + 1));
                                  if (grown.volume() > limit) break;
                                  box = grown;
                              }
                              sums.reset(box, channels.count);
                              depositRun(particles, rests, channels, condensation, inverseVoxel, first, last, sums);
                              addToLeaves(sums, box, channels.count, leaves);
                              first = last;
                          }
                      });
    // Integers: the threads' sums add up to the same in any order.
    LeafMap all;
    for (LeafMap& leaves : threadLeaves) {
        if (all.empty()) {
            all = std::move(leaves);
            continue;
        }
        for (auto& [origin, values] : leaves) {
            LeafSums& into = all[origin];
            if (into.empty()) into = std::move(values);
            else
                for (std::size_t i = 0; i < values.size(); ++i) into[i] += values[i];
        }
    }
    return toGrids(all, channels, rests.size(), transform);
}

double meanRadius(const ParticleSet& particles)
{
    if (particles.size() == 0) return 1.0;
    float largest = 0.0f;
    for (const float r : particles.radius) largest = std::max(largest, std::abs(r));
    const FixedPoint fixed = FixedPoint::forSums(double(largest), particles.size());
    double sum = 0.0;
    for (const float r : particles.radius) sum += fixed(double(r));
    return fixed.value(sum) / double(particles.size());
}

} // namespace vfield
