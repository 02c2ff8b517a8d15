#include "detail_styles.h"

#include <vfield/core/noise.h>
#include <vfield/core/trilinear_sampler.h>

#include <openvdb/tools/Morphology.h>

#include <cmath>
#include <limits>

namespace vfield {

namespace {

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

} // namespace

/// The density resampled on the detail's finer grid and shaped by noise at
/// the interpolated rest position (DetailStyle::Erode and Billows).
openvdb::FloatGrid::Ptr detailedDensity(const openvdb::FloatGrid& density, const std::vector<openvdb::Vec3SGrid::Ptr>& rests,
                                        const std::vector<RestChannel>& channels, const DetailSettings& detail,
                                        double edgeSoftness)
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

} // namespace vfield
