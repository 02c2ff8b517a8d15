#include "detail_styles.h"
#include "surface_distance.h"

#include <vfield/core/noise.h>
#include <vfield/core/trilinear_sampler.h>

#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/Statistics.h>
#include <openvdb/tree/LeafManager.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace vfield {

namespace {

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

    OctaveSplit(const DetailSettings& detail, double coarseVoxel)
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
/// channels: eight lanes' work for six values). The same grids bit for bit
/// as drawn point by point.
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

} // namespace

/// DetailStyle::Displaced: the splat's surface, where its density is
/// edgeSoftness / 2, moved along its normal by billow noise: its coarse
/// octaves on the splat's grid, its fine ones on the detail's grid, only
/// within their own (smaller) range of the surface the coarse ones moved.
/// Split, as a single sum of all the octaves on the detail's grid would
/// visit every fine voxel within the whole range of the splat's surface and
/// draw every octave at each: several times the work.
openvdb::FloatGrid::Ptr displacedDensity(const openvdb::FloatGrid& density, const std::vector<openvdb::Vec3SGrid::Ptr>& rests,
                                         const std::vector<RestChannel>& channels, const DetailSettings& detail,
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
    // around it). The others' blocks are empty, and they are most of the
    // voxels the moved surface could reach: a mask finds them at once, where
    // reading each one's neighbourhood to find so would be much of the cost.
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

} // namespace vfield
