#include <vfield/image/cloud_light.h>

#include <vfield/core/error.h>
#include <vfield/core/image_file.h>

#include <algorithm>
#include <cmath>

namespace vfield {

namespace {

/// Calls visit(sum of the image, sum of the reference) for each block of
/// side x side pixels, on a grid from the image's corner, that lies wholly in the cloud.
template<typename Visit>
void forWholeBlocks(const std::vector<char>& cloud, const std::vector<float>& image, const std::vector<float>& reference,
                    int width, int height, int side, Visit&& visit)
{
    for (int by = 0; by + side <= height; by += side)
        for (int bx = 0; bx + side <= width; bx += side) {
            double blockSum = 0.0, blockReference = 0.0;
            bool whole = true;
            for (int y = by; y < by + side && whole; ++y)
                for (int x = bx; x < bx + side; ++x) {
                    const std::size_t i = std::size_t(y) * std::size_t(width) + std::size_t(x);
                    whole = whole && cloud[i];
                    blockSum += image[i];
                    blockReference += reference[i];
                }
            if (whole) visit(blockSum, blockReference);
        }
}

} // namespace

CloudLightComparison compareCloudLight(const std::vector<float>& image, const std::vector<float>& reference,
                                       const std::vector<float>& clear, int width, int height, const CloudLightOptions& options)
{
    const std::size_t size = std::size_t(width) * std::size_t(height);
    if (image.size() != size || reference.size() != size || clear.size() != size)
        throw ValueError("the render, the reference and the frame without the cloud must all be width x height");
    if (options.block < 1) throw ValueError("a block must be at least a pixel");

    CloudLightComparison c;
    std::vector<char> cloud(size, 0);
    double sum = 0.0, referenceSum = 0.0;
    for (std::size_t i = 0; i < size; ++i) {
        if (!(image[i] - clear[i] > options.threshold)) continue;
        cloud[i] = 1;
        ++c.pixels;
        sum += image[i];
        referenceSum += reference[i];
    }
    if (c.pixels > 0) {
        c.mean = sum / double(c.pixels);
        c.referenceMean = referenceSum / double(c.pixels);
    }
    forWholeBlocks(cloud, image, reference, width, height, options.block, [&](double blockSum, double blockReference) {
        ++c.blocks;
        if (std::abs(blockSum - blockReference) <= options.blockTolerance * blockReference) ++c.blocksWithin;
    });
    for (std::size_t i = 0; i < kRmsBlocks.size(); ++i) {
        double squares = 0.0, referenceBlocks = 0.0;
        long long& blocks = c.rmsBlocks[i];
        forWholeBlocks(cloud, image, reference, width, height, kRmsBlocks[i], [&](double blockSum, double blockReference) {
            ++blocks;
            squares += (blockSum - blockReference) * (blockSum - blockReference);
            referenceBlocks += blockReference;
        });
        if (blocks > 0 && referenceBlocks > 0.0)
            c.relativeRms[i] = std::sqrt(squares / double(blocks)) / (referenceBlocks / double(blocks));
    }
    for (int y = 1; y + 1 < height; ++y)
        for (int x = 1; x + 1 < width; ++x) {
            if (!cloud[std::size_t(y) * std::size_t(width) + std::size_t(x)]) continue;
            double around = 0.0, referenceAround = 0.0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const std::size_t i = std::size_t(y + dy) * std::size_t(width) + std::size_t(x + dx);
                    around += image[i];
                    referenceAround += reference[i];
                }
            if (around > options.speckRatio * referenceAround) ++c.specks;
        }
    return c;
}

namespace {

/// The mean of r, g and b of an OpenEXR image, and its size.
std::vector<float> radiancePlane(const std::string& path, int& width, int& height)
{
    const auto exr = [](const std::string& p) {
        return p.size() > 4 && (p.compare(p.size() - 4, 4, ".exr") == 0 || p.compare(p.size() - 4, 4, ".EXR") == 0);
    };
    if (!exr(path)) throw FileError(path, "light is compared on linear radiance; render OpenEXR frames (--format exr)");
    const OIIO::ImageBuf image = readImageAsFloat(path);
    const OIIO::ImageSpec& spec = image.spec();
    width = spec.width;
    height = spec.height;
    std::vector<float> pixels(std::size_t(width) * std::size_t(height) * std::size_t(spec.nchannels));
    image.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, pixels.data());
    const int channels = std::min(spec.nchannels, 3);
    std::vector<float> plane(std::size_t(width) * std::size_t(height));
    for (std::size_t i = 0; i < plane.size(); ++i) {
        float sum = 0.0f;
        for (int c = 0; c < channels; ++c) sum += pixels[i * std::size_t(spec.nchannels) + std::size_t(c)];
        plane[i] = sum / float(channels);
    }
    return plane;
}

} // namespace

CloudLightComparison compareCloudLight(const std::string& image, const std::string& reference, const std::string& clear,
                                       const CloudLightOptions& options)
{
    int width = 0, height = 0, referenceWidth = 0, referenceHeight = 0, clearWidth = 0, clearHeight = 0;
    const std::vector<float> a = radiancePlane(image, width, height);
    const std::vector<float> b = radiancePlane(reference, referenceWidth, referenceHeight);
    const std::vector<float> c = radiancePlane(clear, clearWidth, clearHeight);
    if (referenceWidth != width || referenceHeight != height || clearWidth != width || clearHeight != height)
        throw ValueError(image + " is " + std::to_string(width) + "x" + std::to_string(height) + ", " + reference + " " +
                         std::to_string(referenceWidth) + "x" + std::to_string(referenceHeight) + ", " + clear + " " +
                         std::to_string(clearWidth) + "x" + std::to_string(clearHeight) + ": they must be the same size");
    return compareCloudLight(a, b, c, width, height, options);
}

} // namespace vfield
