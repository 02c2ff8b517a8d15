// A cloud's light in one render against another: the mean over the cloud's
// pixels and the blocks that agree, as the light tables of docs/rendering.md measure it.

#include "test_meshes.h"

#include <vfield/core/error.h>
#include <vfield/image/cloud_light.h>

#include <catch2/catch.hpp>

#include <OpenImageIO/imagebuf.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

using namespace vfield;

namespace {

constexpr int kWidth = 32, kHeight = 16;

/// A plane of the frame without the cloud (0.2) with a cloud over x < 24 that adds `cloud`.
std::vector<float> frame(float cloud)
{
    std::vector<float> plane(std::size_t(kWidth) * kHeight, 0.2f);
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < 24; ++x) plane[std::size_t(y) * kWidth + std::size_t(x)] += cloud;
    return plane;
}

/// Multiplies the 8x8 block (bx, by) of a plane.
void scaleBlock(std::vector<float>& plane, int bx, int by, float factor)
{
    for (int y = 8 * by; y < 8 * by + 8; ++y)
        for (int x = 8 * bx; x < 8 * bx + 8; ++x) plane[std::size_t(y) * kWidth + std::size_t(x)] *= factor;
}

std::string exrOf(const std::vector<float>& plane, const std::string& path)
{
    OIIO::ImageBuf image(OIIO::ImageSpec(kWidth, kHeight, 3, OIIO::TypeDesc::FLOAT));
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) {
            const float v = plane[std::size_t(y) * kWidth + std::size_t(x)], rgb[3] = {v * 0.9f, v, v * 1.1f};
            image.setpixel(x, y, rgb, 3);
        }
    REQUIRE(image.write(path));
    return path;
}

} // namespace

TEST_CASE("cloud light: the means cover the pixels the cloud brightens and blocks agree within their tolerance", "[image]")
{
    const std::vector<float> clear = frame(0.0f), reference = frame(0.5f);
    std::vector<float> image = reference;
    scaleBlock(image, 0, 0, 1.10f); // within 15%
    scaleBlock(image, 1, 1, 1.30f); // not
    const CloudLightComparison c = compareCloudLight(image, reference, clear, kWidth, kHeight);
    CHECK(c.pixels == 24 * kHeight);
    CHECK(c.referenceMean == Approx(0.7));
    CHECK(c.mean == Approx(0.7 * (4.0 + 1.1 + 1.3) / 6.0));
    CHECK(c.blocks == 6); // the cloud holds 3 x 2 whole blocks; the clear strip none
    CHECK(c.blocksWithin == 5);
    CHECK(c.ratio() == Approx(6.4 / 6.0));
    CHECK_FALSE(c.agrees({})); // the mean 6.7% over
    CloudLightOptions loose;
    loose.meanTolerance = 0.1;
    CHECK_FALSE(c.agrees(loose)); // 5 of 6 blocks (83%) agree, short of 90%
    loose.blockShare = 0.8;
    CHECK(c.agrees(loose));
}

TEST_CASE("cloud light: blotches show in the blocks' relative RMS and a bright pixel as a speck", "[image]")
{
    const std::vector<float> clear = frame(0.0f), reference = frame(0.5f);
    std::vector<float> image = reference;
    // Lumps of 4x4 pixels, 20% over and under in turn: 4x4 blocks see all
    // of them, 8x8 blocks each hold two that cancel.
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < 24; ++x) image[std::size_t(y) * kWidth + std::size_t(x)] *= (x / 4 + y / 4) % 2 ? 1.2f : 0.8f;
    const CloudLightComparison c = compareCloudLight(image, reference, clear, kWidth, kHeight);
    CHECK(c.rmsBlocks == std::array<long long, 2>{24, 6});
    CHECK(c.relativeRms[0] == Approx(0.2));
    CHECK(c.relativeRms[1] == Approx(0.0).margin(1e-6));
    CHECK(c.specks == 0);
    CloudLightOptions asked;
    asked.rmsTolerance = {0.08, 0.05};
    CHECK_FALSE(c.agrees(asked));
    asked.rmsTolerance = {0.25, 0.05};
    CHECK(c.agrees(asked));

    // One pixel 20 times as bright lifts its 3x3 neighbourhood's light
    // (9 x 0.7) by 19 x 0.7 past twice the reference's: a speck in each of
    // the nine windows that hold it.
    std::vector<float> speckled = reference;
    speckled[std::size_t(8) * kWidth + 12] *= 20.0f;
    const CloudLightComparison s = compareCloudLight(speckled, reference, clear, kWidth, kHeight);
    CHECK(s.specks == 9);
    CloudLightOptions loose; // its mean (5% over) and its block (30%) let pass
    loose.meanTolerance = 0.1;
    loose.blockShare = 0.8;
    CHECK(s.agrees(loose));
    loose.specksAllowed = 0;
    CHECK_FALSE(s.agrees(loose));
}

TEST_CASE("cloud light: a render that adds nothing over the clear frame has no cloud and does not agree", "[image]")
{
    const std::vector<float> clear = frame(0.0f);
    const CloudLightComparison c = compareCloudLight(clear, frame(0.5f), clear, kWidth, kHeight);
    CHECK(c.pixels == 0);
    CHECK(c.blocks == 0);
    CHECK_FALSE(c.agrees({}));
}

TEST_CASE("cloud light: files are read as linear OpenEXR; a PNG or another size is refused naming the files", "[image]")
{
    const std::string dir = test::scratchDir("cloud-light");
    std::vector<float> image = frame(0.5f);
    scaleBlock(image, 2, 0, 1.02f);
    const CloudLightComparison c = compareCloudLight(exrOf(image, dir + "/fast.exr"), exrOf(frame(0.5f), dir + "/reference.exr"),
                                                     exrOf(frame(0.0f), dir + "/clear.exr"));
    CHECK(c.pixels == 24 * kHeight);
    CHECK(c.blocksWithin == 6);
    CHECK(c.ratio() == Approx(1.0 + 0.02 / 6.0));
    CHECK(c.agrees({}));
    CHECK_THROWS_WITH(compareCloudLight(dir + "/fast.png", dir + "/reference.exr", dir + "/clear.exr"),
                      Catch::Contains(dir + "/fast.png") && Catch::Contains("--format exr"));
    OIIO::ImageBuf small(OIIO::ImageSpec(8, 8, 3, OIIO::TypeDesc::FLOAT));
    REQUIRE(small.write(dir + "/small.exr"));
    CHECK_THROWS_AS(compareCloudLight(dir + "/fast.exr", dir + "/small.exr", dir + "/clear.exr"), ValueError);
}
