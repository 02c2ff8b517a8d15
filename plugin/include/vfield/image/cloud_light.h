#pragma once
/// @file cloud_light.h
/// A cloud's light in one render measured against another of the same frame:
/// the fast integrator against the reference path tracer, as the tables of
/// docs/rendering.md ("Accuracy") measure it. The cloud's pixels are those
/// the first render lights: brighter than the same frame rendered without the cloud
/// (render.extinction = 0) by more than `threshold` in the mean of r, g and
/// b. Over them, the two renders' mean radiances; over the blocks of `block`
/// x `block` pixels (a grid from the image's corner) that lie wholly in the
/// cloud, the share whose two means agree within `blockTolerance`. The
/// structure a mean hides: the RMS of the blocks' differences relative to the
/// reference's mean block, for blocks of 4 and 8 pixels (blotches a few
/// pixels across show at 4 and fade by 8, where noise alone falls by half),
/// and the specks, cloud pixels whose 3x3 neighbourhood is more than
/// `speckRatio` times as bright as the reference's. Images are compared as
/// linear radiance: OpenEXR files (`--format exr`).

#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace vfield {

struct CloudLightOptions {
    double threshold = 1e-4;      ///< linear radiance a cloud pixel adds, at least (mean of r, g, b)
    int block = 8;                ///< pixels, the side of a block (>= 1)
    double blockTolerance = 0.15; ///< a block agrees when its means differ by at most this, relative to the reference's
    double meanTolerance = 0.05;  ///< the renders agree when their means differ by at most this, relative
    double blockShare = 0.9;      ///< ... and at least this share of the blocks agree
    double speckRatio = 2.0;      ///< a speck is this many times the reference's light over 3x3 pixels
    /// The largest relative RMS of the blocks of kRmsBlocks' sides; unchecked when negative.
    std::array<double, 2> rmsTolerance{-1.0, -1.0};
    long long specksAllowed = -1; ///< unchecked when negative
};

/// The sides of the blocks the relative RMS is measured over, pixels.
inline constexpr std::array<int, 2> kRmsBlocks{4, 8};

struct CloudLightComparison {
    long long pixels = 0;                   ///< the cloud's
    double mean = 0.0, referenceMean = 0.0; ///< mean of r, g, b over the cloud's pixels
    long long blocks = 0, blocksWithin = 0; ///< blocks wholly in the cloud; those that agree
    /// Over the whole blocks of kRmsBlocks' sides: sqrt(mean (block - reference's)^2) / the reference's mean block.
    std::array<double, 2> relativeRms{0.0, 0.0};
    std::array<long long, 2> rmsBlocks{0, 0}; ///< how many blocks each is over
    long long specks = 0;                     ///< cloud pixels brighter than speckRatio x the reference over 3x3

    double ratio() const { return referenceMean > 0.0 ? mean / referenceMean : 0.0; }
    double shareWithin() const { return blocks > 0 ? double(blocksWithin) / double(blocks) : 0.0; }
    bool meansAgree(const CloudLightOptions& options) const { return std::abs(ratio() - 1.0) <= options.meanTolerance; }
    /// A cloud with no whole block passes on its mean alone.
    bool blocksAgree(const CloudLightOptions& options) const { return blocks == 0 || shareWithin() >= options.blockShare; }
    bool rmsWithin(const CloudLightOptions& options, std::size_t i) const
    {
        return options.rmsTolerance[i] < 0.0 || relativeRms[i] <= options.rmsTolerance[i];
    }
    bool specksWithin(const CloudLightOptions& options) const
    {
        return options.specksAllowed < 0 || specks <= options.specksAllowed;
    }
    /// A cloud, its means within meanTolerance, enough blocks within
    /// blockTolerance, and the RMS and specks within what is asked of them.
    bool agrees(const CloudLightOptions& options) const
    {
        return pixels > 0 && meansAgree(options) && blocksAgree(options) && rmsWithin(options, 0) && rmsWithin(options, 1) &&
               specksWithin(options);
    }
};

/// Planes of the mean of r, g and b, width x height, x fastest: the render,
/// the reference and the frame without the cloud. Throws ValueError when
/// their sizes differ or the block is smaller than a pixel.
CloudLightComparison compareCloudLight(const std::vector<float>& image, const std::vector<float>& reference,
                                       const std::vector<float>& clear, int width, int height,
                                       const CloudLightOptions& options = {});

/// The same from OpenEXR files. Throws FileError naming a file that cannot
/// be read or is not OpenEXR (a PNG holds sRGB, not radiance), ValueError
/// naming the files when their sizes differ.
CloudLightComparison compareCloudLight(const std::string& image, const std::string& reference, const std::string& clear,
                                       const CloudLightOptions& options = {});

} // namespace vfield
