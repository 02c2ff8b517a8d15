#include <vfield/render/frame_image.h>

#include <vfield/core/error.h>
#include <vfield/core/image_file.h>

#include <OpenImageIO/imagebufalgo.h>

#include <nlohmann/json.hpp>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace vfield {

float linearToSrgb(float v)
{
    v = std::clamp(v, 0.0f, 1.0f);
    return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

namespace {

bool endsWith(const std::string& text, const std::string& tail)
{
    return text.size() >= tail.size() && text.compare(text.size() - tail.size(), tail.size(), tail) == 0;
}

} // namespace

OIIO::ImageBuf toDisplay(const RenderImage& image, const DisplayView& view)
{
    OIIO::ImageBuf buf(OIIO::ImageSpec(image.width, image.height, 3, OIIO::TypeDesc::FLOAT));
    float* display = static_cast<float*>(buf.localpixels()); // a new ImageBuf's pixels: contiguous, rows top-down
    const std::size_t pixels = std::size_t(image.width) * image.height;
    tbb::parallel_for(std::size_t(0), pixels, [&](std::size_t i) {
        for (int c = 0; c < 3; ++c) display[3 * i + c] = image.rgba[4 * i + c];
    });
    view.apply(display, pixels);
    return buf;
}

OIIO::ImageBuf toDisplay(const OIIO::ImageBuf& linear, const DisplayView& view)
{
    const OIIO::ImageSpec& spec = linear.spec();
    if (spec.nchannels < 3) throw FileError(linear.name(), "expected R, G and B channels");
    OIIO::ImageBuf buf(OIIO::ImageSpec(spec.width, spec.height, 3, OIIO::TypeDesc::FLOAT));
    if (!linear.get_pixels(OIIO::ROI(spec.x, spec.x + spec.width, spec.y, spec.y + spec.height, 0, 1, 0, 3),
                           OIIO::TypeDesc::FLOAT, buf.localpixels()))
        throw FileError(linear.name(), "cannot read the image: " + linear.geterror());
    view.apply(static_cast<float*>(buf.localpixels()), std::size_t(spec.width) * spec.height);
    return buf;
}

namespace {

/// A layer of the linear image: its channels' names, and where its values are
/// (channels.size() floats a pixel).
struct Layer {
    std::vector<std::string> channels;
    const std::vector<float>* values;
};

std::vector<Layer> layersOf(const RenderImage& image)
{
    std::vector<Layer> layers{{{"R", "G", "B", "A"}, &image.rgba}, {{"Z"}, &image.depth}};
    const RenderPasses& passes = image.passes;
    if (passes.empty()) return layers;
    layers.push_back({{"cloud.R", "cloud.G", "cloud.B", "cloud.A"}, &passes.cloud});
    layers.push_back({{"surfaces.R", "surfaces.G", "surfaces.B", "surfaces.A"}, &passes.surfaces});
    layers.push_back({{"shadow.X"}, &passes.shadow});
    layers.push_back({{"normal.X", "normal.Y", "normal.Z"}, &passes.normal});
    layers.push_back({{"objectIndex.X"}, &passes.objectIndex});
    layers.push_back({{"vector.X", "vector.Y", "vector.Z", "vector.W"}, &passes.vector});
    return layers;
}

} // namespace

OIIO::ImageBuf toLinear(const RenderImage& image)
{
    const std::vector<Layer> layers = layersOf(image);
    std::vector<std::string> names;
    for (const Layer& layer : layers) names.insert(names.end(), layer.channels.begin(), layer.channels.end());
    const int channels = int(names.size());
    OIIO::ImageSpec spec(image.width, image.height, channels, OIIO::TypeDesc::FLOAT);
    spec.channelnames = names;
    spec.alpha_channel = 3;
    spec.z_channel = 4;
    spec.attribute("colorSpace", kWorkingSpaceName);
    spec.attribute("chromaticities", OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, 8), kWorkingSpaceChromaticities);
    if (!image.passes.empty()) {
        // The objects objectIndex.X counts, as {"1": "terrain", ...}.
        nlohmann::json objects = nlohmann::json::object();
        for (std::size_t i = 0; i < image.passes.objectNames.size(); ++i)
            objects[std::to_string(i + 1)] = image.passes.objectNames[i];
        spec.attribute("vfield:objectIndex", objects.dump());
    }
    OIIO::ImageBuf buf(spec);
    float* linear = static_cast<float*>(buf.localpixels());
    tbb::parallel_for(0, image.height, [&](int y) {
        for (std::size_t i = std::size_t(y) * image.width; i < std::size_t(y + 1) * image.width; ++i) {
            float* out = &linear[std::size_t(channels) * i];
            for (const Layer& layer : layers) {
                const std::size_t n = layer.channels.size();
                for (std::size_t c = 0; c < n; ++c) *out++ = (*layer.values)[n * i + c];
            }
        }
    });
    return buf;
}

void writeFrameImage(const RenderImage& image, const std::string& path, const DisplayView& view, ExrDepth exrDepth)
{
    if (endsWith(path, ".png")) writeImage(toDisplay(image, view), path);
    else if (endsWith(path, ".exr"))
        writeImage(toLinear(image), path, exrDepth == ExrDepth::Float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::HALF);
    else throw FileError(path, "frames are written as .png or .exr");
}

void writeSideBySide(const std::string& left, const std::string& right, const std::string& path)
{
    OIIO::ImageBuf a(left), b(right);
    for (OIIO::ImageBuf* image : {&a, &b})
        if (!image->read(0, 0, true, OIIO::TypeDesc::FLOAT)) throw FileError(image->name(), "cannot read: " + image->geterror());
    const int channels = std::min(a.nchannels(), b.nchannels());
    OIIO::ImageBuf both(OIIO::ImageSpec(a.spec().width + b.spec().width, std::max(a.spec().height, b.spec().height), channels,
                                        OIIO::TypeDesc::FLOAT));
    const OIIO::ROI channelsOfBoth(0, a.spec().width, 0, a.spec().height, 0, 1, 0, channels);
    if (!OIIO::ImageBufAlgo::paste(both, 0, 0, 0, 0, a, channelsOfBoth) ||
        !OIIO::ImageBufAlgo::paste(both, a.spec().width, 0, 0, 0, b,
                                   OIIO::ROI(0, b.spec().width, 0, b.spec().height, 0, 1, 0, channels)))
        throw FileError(path, "cannot compose the images: " + both.geterror());
    writeImage(both, path);
}

} // namespace vfield
