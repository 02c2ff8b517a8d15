// Images compared as idiff compares them: statistics, thresholds, verdicts.

#include "test_meshes.h"

#include <vfield/core/error.h>
#include <vfield/image/image_compare.h>

#include <catch2/catch.hpp>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <filesystem>
#include <limits>

using namespace vfield;

namespace {

/// A 10x10 grey image; `bump` brightens red at (3, 4), `nudge` green at (7, 1).
std::string greyImage(const std::string& dir, const std::string& name, float bump, float nudge, int width = 10)
{
    OIIO::ImageBuf image(OIIO::ImageSpec(width, 10, 3, OIIO::TypeDesc::FLOAT));
    const float grey[3] = {0.5f, 0.5f, 0.5f};
    OIIO::ImageBufAlgo::fill(image, grey);
    const float bumped[3] = {0.5f + bump, 0.5f, 0.5f}, nudged[3] = {0.5f, 0.5f + nudge, 0.5f};
    image.setpixel(3, 4, bumped, 3);
    image.setpixel(7, 1, nudged, 3);
    const std::string path = dir + "/" + name;
    REQUIRE(image.write(path));
    return path;
}

} // namespace

TEST_CASE("image compare: an image equals itself with zero error", "[compare]")
{
    const std::string dir = test::scratchDir("image-compare-same");
    const std::string a = greyImage(dir, "a.exr", 0.0f, 0.0f);
    const ImageComparison same = compareImages(a, a);
    CHECK(same.verdict == CompareVerdict::Pass);
    CHECK(same.maxError == 0.0);
    CHECK(same.pixels == 100);
    CHECK(same.pixelsOverFail == 0);
}

TEST_CASE("image compare: statistics locate the largest difference and count pixels over thresholds", "[compare]")
{
    const std::string dir = test::scratchDir("image-compare-stats");
    const std::string a = greyImage(dir, "a.exr", 0.0f, 0.0f), b = greyImage(dir, "b.exr", 0.1f, 0.01f);
    ImageCompareOptions options;
    options.diffPath = dir + "/diff.exr";
    options.diffScale = 10.0;
    const ImageComparison c = compareImages(a, b, options);
    CHECK(c.verdict == CompareVerdict::Fail);
    CHECK(c.maxError == Approx(0.1).epsilon(1e-5));
    CHECK(c.maxX == 3);
    CHECK(c.maxY == 4);
    CHECK(c.maxChannel == 0);
    CHECK(c.pixelsOverFail == 2);
    CHECK(c.percentOverFail() == Approx(2.0));
    // Mean over every channel of every pixel: (0.1 + 0.01) / 300.
    CHECK(c.meanError == Approx(0.11 / 300.0).epsilon(1e-4));

    // The difference image holds |a - b| times the scale.
    OIIO::ImageBuf diff(options.diffPath);
    REQUIRE(diff.read(0, 0, true, OIIO::TypeDesc::FLOAT));
    float pixel[3];
    diff.getpixel(3, 4, pixel, 3);
    CHECK(pixel[0] == Approx(1.0).epsilon(1e-4));
    diff.getpixel(0, 0, pixel, 3);
    CHECK(pixel[0] == 0.0f);
}

TEST_CASE("image compare: verdicts follow idiff's fail, fail-percent, hard-fail and warn rules", "[compare]")
{
    const std::string dir = test::scratchDir("image-compare-verdicts");
    const std::string a = greyImage(dir, "a.exr", 0.0f, 0.0f), b = greyImage(dir, "b.exr", 0.1f, 0.01f);
    const auto verdict = [&](double fail, double failPercent, double hardFail, double warn) {
        ImageCompareOptions options;
        options.failThreshold = fail;
        options.failPercent = failPercent;
        options.hardFail = hardFail;
        options.warnThreshold = warn;
        return compareImages(a, b, options).verdict;
    };
    const double none = std::numeric_limits<double>::infinity();
    CHECK(verdict(0.005, 2.0, none, 1.0) == CompareVerdict::Pass); // 2 pixels of 100 over: 2% allowed
    CHECK(verdict(0.005, 1.0, none, 1.0) == CompareVerdict::Fail);
    CHECK(verdict(0.05, 1.0, none, 1.0) == CompareVerdict::Pass); // only the 0.1 pixel is over 0.05
    CHECK(verdict(0.05, 1.0, 0.09, 1.0) == CompareVerdict::Fail); // no difference may exceed 0.09
    CHECK(verdict(0.2, 0.0, none, 0.005) == CompareVerdict::Warn);
}

TEST_CASE("image compare: different sizes fail and a missing image is an error naming it", "[compare]")
{
    const std::string dir = test::scratchDir("image-compare-errors");
    const std::string a = greyImage(dir, "a.exr", 0.0f, 0.0f), wide = greyImage(dir, "wide.exr", 0.0f, 0.0f, 12);
    const ImageComparison sizes = compareImages(a, wide);
    CHECK(sizes.verdict == CompareVerdict::Fail);
    CHECK(sizes.sizeMismatch == "10x10 vs 12x10");
    try {
        compareImages(a, dir + "/none.exr");
        FAIL("a missing image compared");
    } catch (const FileError& e) {
        CHECK(std::string(e.what()).rfind(dir + "/none.exr: cannot read the image", 0) == 0);
    }
    CHECK_FALSE(std::filesystem::exists(dir + "/none.exr"));
}
