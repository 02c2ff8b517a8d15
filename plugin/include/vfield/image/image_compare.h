#pragma once
/// @file image_compare.h
/// Two images compared as OpenImageIO's idiff compares them
/// (ImageBufAlgo::compare): per-pixel absolute differences of the channels the
/// two share; a pixel is over a threshold when any channel is.
///
/// Verdict, as idiff's: Fail when more than failPercent % of the pixels are
/// over failThreshold, or any difference exceeds hardFail, or the sizes
/// differ; otherwise Warn when more than warnPercent % are over warnThreshold;
/// otherwise Pass.

#include <limits>
#include <string>

namespace vfield {

struct ImageCompareOptions {
    double failThreshold = 1e-6;                               ///< per-channel difference (pixel values in [0, 1])
    double failPercent = 0.0;                                  ///< % of pixels allowed over failThreshold
    double hardFail = std::numeric_limits<double>::infinity(); ///< no difference may exceed this
    double warnThreshold = 1e-6;
    double warnPercent = 0.0;
    /// Where to write |A - B| x diffScale as an image (empty: nowhere).
    std::string diffPath;
    double diffScale = 10.0;
};

enum class CompareVerdict { Pass, Warn, Fail };

struct ImageComparison {
    CompareVerdict verdict = CompareVerdict::Pass;
    std::string sizeMismatch; ///< "320x180 vs 160x90" when the sizes differ (then no statistics)
    double meanError = 0.0, rmsError = 0.0, psnr = 0.0, maxError = 0.0;
    int maxX = 0, maxY = 0, maxChannel = 0; ///< where the largest difference is
    long long pixels = 0, pixelsOverFail = 0, pixelsOverWarn = 0;

    double percentOverFail() const { return pixels ? 100.0 * double(pixelsOverFail) / double(pixels) : 0.0; }
    double percentOverWarn() const { return pixels ? 100.0 * double(pixelsOverWarn) / double(pixels) : 0.0; }
};

/// Throws FileError when an image cannot be read or the diff cannot be written.
ImageComparison compareImages(const std::string& pathA, const std::string& pathB, const ImageCompareOptions& options = {});

} // namespace vfield
