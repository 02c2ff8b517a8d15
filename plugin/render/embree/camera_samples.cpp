#include <vfield/render/embree/camera_samples.h>

#include <vfield/render/frame_image.h>

#include <cmath>

namespace vfield {

RenderPasses allocatePasses(int width, int height)
{
    const std::size_t pixels = std::size_t(width) * height;
    RenderPasses passes;
    passes.cloud.assign(4 * pixels, 0.0f);
    passes.surfaces.assign(4 * pixels, 0.0f);
    passes.shadow.assign(pixels, 0.0f);
    passes.normal.assign(3 * pixels, 0.0f);
    passes.objectIndex.assign(pixels, 0.0f);
    passes.vector.assign(4 * pixels, 0.0f);
    return passes;
}

std::vector<uint8_t> pixelsThatStandOut(const RenderImage& firstSamples, double threshold)
{
    const int width = firstSamples.width, height = firstSamples.height;
    const std::size_t pixels = std::size_t(width) * height;
    // Display values: sRGB-encoded colour, and coverage.
    std::vector<std::array<float, 4>> shown(pixels);
    tbb::parallel_for(std::size_t(0), pixels, [&](std::size_t pixel) {
        const float* rgba = &firstSamples.rgba[4 * pixel];
        shown[pixel] = {linearToSrgb(rgba[0]), linearToSrgb(rgba[1]), linearToSrgb(rgba[2]), rgba[3]};
    });
    const auto differ = [&](std::size_t a, std::size_t b) {
        for (int c = 0; c < 4; ++c)
            if (std::abs(shown[a][c] - shown[b][c]) > threshold) return true;
        return false;
    };
    std::vector<uint8_t> standOut(pixels, 0);
    // Each pixel against its right and lower neighbours, both flagged; a
    // row's flags set by its own pass and the one above it, in order.
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const std::size_t pixel = std::size_t(y) * width + x;
            if (x + 1 < width && differ(pixel, pixel + 1)) standOut[pixel] = standOut[pixel + 1] = 1;
            if (y + 1 < height && differ(pixel, pixel + width)) standOut[pixel] = standOut[pixel + width] = 1;
        }
    return standOut;
}

} // namespace vfield
