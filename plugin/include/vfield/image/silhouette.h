#pragma once
/// @file silhouette.h
/// How rough a cloud's outline is, measured on the images themselves: the
/// box-counting dimension of the boundary of the pixels the cloud brightens,
/// against the same frame rendered without it (render.extinction = 0; its
/// shadows, which darken, are not the cloud), or of the pixels a frame's
/// alpha shows covered (measureOpacitySilhouette: the density's outline,
/// whatever the light). A disk's outline measures 1; real clouds' perimeters measure 1.33 to 1.35
/// over six decades of size (Lovejoy 1982, Science 216:185); smooth, blobby
/// volumes 1.1 or less.
///
/// Boundary pixels are cloud pixels with a non-cloud 4-neighbour (the
/// image's border does not count as an outline). N(s) counts the boxes of s
/// x s pixels, on a grid from the image's corner, that hold a boundary pixel,
/// for s = smallestBox, 2 smallestBox, ... up to largestBox; the dimension is
/// the least-squares slope of log N(s) against log(1 / s).

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace vfield {

struct SilhouetteOptions {
    double threshold = 2.0 / 255.0; ///< a pixel is cloud where any channel is brighter by more, or its alpha more (0..1)
    int smallestBox = 2;            ///< pixels, a power of two
    int largestBox = 64;            ///< pixels, a power of two
};

struct SilhouetteMeasure {
    double dimension = 0.0;                           ///< box-counting dimension of the outline
    double coverage = 0.0;                            ///< fraction of the pixels that are cloud
    long long boundaryPixels = 0;                     ///< pixels of the outline
    std::vector<std::pair<int, long long>> boxCounts; ///< (s, N(s)), s ascending
};

/// The measure of a mask (width x height, x fastest, non-zero: cloud).
/// Throws ValueError for box sizes that are not powers of two in order.
SilhouetteMeasure measureSilhouette(const std::vector<uint8_t>& mask, int width, int height,
                                    const SilhouetteOptions& options = {});

/// The measure of the cloud in `withCloud` against `withoutCloud`, the same
/// frame rendered without it. Throws FileError naming an image that cannot
/// be read, ValueError when their sizes differ.
SilhouetteMeasure measureSilhouette(const std::string& withCloud, const std::string& withoutCloud,
                                    const SilhouetteOptions& options = {});

/// The measure of the pixels a frame's alpha shows covered by more than
/// options.threshold: with a transparent sky and nothing but cloud in view,
/// the cloud's own opacity, 1 - e^-(optical depth along the pixel's ray), so
/// the outline is the density's whatever the light (the pixels the cloud
/// brightens also follow the edges of its shadowed parts, so that a cloud
/// measures rougher with its base drawn black than lit grey, and either
/// rougher than its opacity). Throws
/// FileError naming an image that cannot be read, ValueError for one
/// without alpha.
SilhouetteMeasure measureOpacitySilhouette(const std::string& frame, const SilhouetteOptions& options = {});

} // namespace vfield
