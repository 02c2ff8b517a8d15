#include <vfield/image/image_compare.h>

#include <vfield/core/error.h>
#include <vfield/core/image_file.h>

#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>

namespace vfield {

ImageComparison compareImages(const std::string& pathA, const std::string& pathB, const ImageCompareOptions& options)
{
    const OIIO::ImageBuf a = readImageAsFloat(pathA), b = readImageAsFloat(pathB);
    ImageComparison result;
    const OIIO::ImageSpec &sa = a.spec(), &sb = b.spec();
    if (sa.width != sb.width || sa.height != sb.height || sa.depth != sb.depth) {
        result.sizeMismatch = std::to_string(sa.width) + "x" + std::to_string(sa.height) + " vs " + std::to_string(sb.width) +
                              "x" + std::to_string(sb.height);
        result.verdict = CompareVerdict::Fail;
        return result;
    }
    const OIIO::ROI shared(0, sa.width, 0, sa.height, 0, 1, 0, std::min(sa.nchannels, sb.nchannels));
    const OIIO::ImageBufAlgo::CompareResults r =
        OIIO::ImageBufAlgo::compare(a, b, float(options.failThreshold), float(options.warnThreshold), 0.0f, 0.0f, shared);
    // OIIO 2.4 raises r.error whenever a pixel fails, so it does not signal errors here: reading did.
    result.meanError = r.meanerror;
    result.rmsError = r.rms_error;
    result.psnr = r.PSNR;
    result.maxError = r.maxerror;
    result.maxX = r.maxx;
    result.maxY = r.maxy;
    result.maxChannel = r.maxc;
    result.pixels = (long long)sa.width * sa.height;
    result.pixelsOverFail = (long long)r.nfail;
    result.pixelsOverWarn = (long long)r.nwarn;

    if (double(r.nfail) > options.failPercent / 100.0 * double(result.pixels) || r.maxerror > options.hardFail)
        result.verdict = CompareVerdict::Fail;
    else if (double(r.nwarn) > options.warnPercent / 100.0 * double(result.pixels)) result.verdict = CompareVerdict::Warn;

    if (!options.diffPath.empty()) {
        OIIO::ImageBuf difference = OIIO::ImageBufAlgo::absdiff(a, b, shared);
        difference = OIIO::ImageBufAlgo::mul(difference, float(options.diffScale));
        if (difference.has_error())
            throw FileError(options.diffPath, "cannot make the difference image: " + difference.geterror());
        writeImage(difference, options.diffPath);
    }
    return result;
}

} // namespace vfield
