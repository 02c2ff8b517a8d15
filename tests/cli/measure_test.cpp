#include "test_meshes.h"

#include <vfield/core/vdb_file.h>
#include <vfield/host/versions.h>
#include <vfield/mesh/mesh_io.h>
#include <vfield/render/povray/povray_runner.h>

#include <embree3/rtcore_config.h>
#include <openvdb/version.h>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <thread>

#include <nlohmann/json.hpp>

namespace {

using Run = vfield::test::CliRun;
using vfield::test::lineCount;
using vfield::test::runVfieldCli;

/// What `vfield silhouette` printed: the outline's dimension, the cloud's share of the pixels.
struct SilhouetteLine {
    double dimension = 0.0, percent = 0.0;
};
SilhouetteLine silhouetteOf(const Run& measure)
{
    REQUIRE(measure.exitCode == 0);
    INFO(measure.out);
    SilhouetteLine line;
    REQUIRE(std::sscanf(measure.out.c_str(), "dimension %lf, cloud %lf%%", &line.dimension, &line.percent) == 2);
    return line;
}

/// The silhouette tests' disk, 60 pixels in radius in a 256x256 frame, as measured.
void checkIsTheDisk(const Run& measure)
{
    INFO(measure.out);
    const SilhouetteLine disk = silhouetteOf(measure);
    CHECK(disk.dimension == Approx(1.0).margin(0.06));
    CHECK(disk.percent == Approx(100.0 * M_PI * 60 * 60 / (256 * 256)).epsilon(0.02));
}

} // namespace

TEST_CASE("cli: compare follows idiff's thresholds and exits 0 pass, 1 fail, 2 error", "[cli][compare]")
{
    const std::string dir = vfield::test::scratchDir("cli-compare");
    // A 10x10 grey image, and a copy with one pixel 0.1 brighter and one 0.01.
    const auto write = [&](const std::string& name, float bump, float nudge) {
        OIIO::ImageBuf image(OIIO::ImageSpec(10, 10, 3, OIIO::TypeDesc::FLOAT));
        const float grey[3] = {0.5f, 0.5f, 0.5f};
        OIIO::ImageBufAlgo::fill(image, grey);
        const float bumped[3] = {0.5f + bump, 0.5f, 0.5f}, nudged[3] = {0.5f, 0.5f + nudge, 0.5f};
        image.setpixel(3, 4, bumped, 3);
        image.setpixel(7, 1, nudged, 3);
        REQUIRE(image.write(dir + "/" + name));
    };
    write("a.exr", 0.0f, 0.0f);
    write("b.exr", 0.1f, 0.01f);
    const auto compare = [&](const std::string& arguments) { return runVfieldCli("compare " + arguments, dir); };

    const Run same = compare(dir + "/a.exr " + dir + "/a.exr");
    CHECK(same.exitCode == 0);
    CHECK(same.out.find("PASS") != std::string::npos);
    const Run differ = compare(dir + "/a.exr " + dir + "/b.exr --diff " + dir + "/d.png");
    CHECK(differ.exitCode == 1);
    CHECK(differ.out.find("2 pixels (2%) over 1e-06") != std::string::npos);
    CHECK(differ.out.find("Max error = 0.1 @ (3, 4, channel 0)") != std::string::npos);
    CHECK(std::filesystem::exists(dir + "/d.png"));
    // 2 of 100 pixels over 0.005: 2% allowed passes, 1% fails; a hard limit below 0.1 fails.
    CHECK(compare(dir + "/a.exr " + dir + "/b.exr --fail 0.005 --fail-percent 2").exitCode == 0);
    CHECK(compare(dir + "/a.exr " + dir + "/b.exr --fail 0.005 --fail-percent 1").exitCode == 1);
    CHECK(compare(dir + "/a.exr " + dir + "/b.exr --fail 0.05 --fail-percent 1").exitCode == 0);
    CHECK(compare(dir + "/a.exr " + dir + "/b.exr --fail 0.05 --fail-percent 1 --hard-fail 0.09").exitCode == 1);
    const Run warned = compare(dir + "/a.exr " + dir + "/b.exr --fail 0.2 --warn 0.005");
    CHECK(warned.exitCode == 0);
    CHECK(warned.out.find("WARNING") != std::string::npos);

    // --cloud: the cloud's light in a against b, over the pixels a lights
    // above the frame without it (black here): one whole 8x8 block.
    OIIO::ImageBuf black(OIIO::ImageSpec(10, 10, 3, OIIO::TypeDesc::FLOAT));
    OIIO::ImageBufAlgo::zero(black);
    REQUIRE(black.write(dir + "/clear.exr"));
    const std::string light = dir + "/a.exr " + dir + "/b.exr --cloud " + dir + "/clear.exr";
    const Run agrees = compare(light);
    CHECK(agrees.exitCode == 0);
    CHECK(agrees.out.find("100 cloud pixels") != std::string::npos);
    CHECK(agrees.out.find("1 of 1 blocks of 8x8 pixels within 0.15") != std::string::npos);
    CHECK(compare(light + " --mean-tolerance 0").exitCode == 1);
    const Run png = compare(dir + "/a.png " + dir + "/b.exr --cloud " + dir + "/clear.exr");
    CHECK(png.exitCode == 2);
    CHECK(png.err.find(dir + "/a.png: light is compared on linear radiance") != std::string::npos);
    CHECK(lineCount(png.err) == 1);

    const Run missing = compare(dir + "/a.exr " + dir + "/none.exr");
    CHECK(missing.exitCode == 2);
    CHECK(missing.err.rfind("vfield compare: " + dir + "/none.exr: cannot read the image", 0) == 0);
    CHECK(lineCount(missing.err) == 1);

    // VDB files: voxel by voxel within a tolerance.
    openvdb::initialize();
    const auto grid = [](float value) {
        openvdb::FloatGrid::Ptr g = openvdb::FloatGrid::create(0.0f);
        g->setName("density");
        g->tree().setValue(openvdb::Coord(1, 2, 3), 1.0f);
        g->tree().setValue(openvdb::Coord(4, 5, 6), value);
        return g;
    };
    vfield::writeVdb(dir + "/a.vdb", {grid(2.0f)});
    vfield::writeVdb(dir + "/b.vdb", {grid(2.001f)});
    const Run vdbDiffer = compare(dir + "/a.vdb " + dir + "/b.vdb");
    CHECK(vdbDiffer.exitCode == 1);
    CHECK(vdbDiffer.out.find("density (float): 1 of 2 voxels differ") != std::string::npos);
    CHECK(compare(dir + "/a.vdb " + dir + "/b.vdb --tolerance 0.01").exitCode == 0);
    CHECK(compare(dir + "/a.vdb " + dir + "/a.exr").exitCode == 2);
}

TEST_CASE("cli: silhouette measures the outline of what a frame brightens against its clear twin", "[cli]")
{
    const std::string dir = vfield::test::scratchDir("cli-silhouette");
    // A dark 256x256 ground, and the same with a white disk on it and a dark
    // shadow beside it: the shadow darkens, so only the disk is cloud.
    const auto write = [&](const std::string& name, bool cloud, int width) {
        OIIO::ImageBuf image(OIIO::ImageSpec(width, 256, 3, OIIO::TypeDesc::UINT8));
        const float ground[3] = {0.3f, 0.4f, 0.2f}, white[3] = {0.9f, 0.9f, 0.9f}, shadow[3] = {0.1f, 0.1f, 0.1f};
        OIIO::ImageBufAlgo::fill(image, ground);
        if (cloud)
            for (int y = 0; y < 256; ++y)
                for (int x = 0; x < width; ++x) {
                    if (std::hypot(x - 100.0, y - 128.0) < 60.0) image.setpixel(x, y, white, 3);
                    else if (x > 180 && x < 250 && y > 20 && y < 60) image.setpixel(x, y, shadow, 3);
                }
        REQUIRE(image.write(dir + "/" + name));
    };
    write("clear.png", false, 256);
    write("cloud.png", true, 256);
    write("wide.png", false, 300);

    checkIsTheDisk(runVfieldCli("silhouette " + dir + "/cloud.png " + dir + "/clear.png", dir));

    const Run mismatched = runVfieldCli("silhouette " + dir + "/cloud.png " + dir + "/wide.png", dir);
    CHECK(mismatched.exitCode != 0);
    CHECK(mismatched.err.find("cloud.png is 256x256 but " + dir + "/wide.png is 300x256") != std::string::npos);
    CHECK(lineCount(mismatched.err) == 1);
}

TEST_CASE("cli: silhouette --opacity measures what a frame's alpha covers, whatever its colour", "[cli]")
{
    const std::string dir = vfield::test::scratchDir("cli-silhouette-opacity");
    // Black sky (alpha 0), a disk of cloud half of it lit and half black: the
    // colour has an edge across the disk, its alpha only the disk's outline.
    OIIO::ImageBuf frame(OIIO::ImageSpec(256, 256, 4, OIIO::TypeDesc::HALF));
    const float lit[4] = {0.9f, 0.9f, 0.9f, 1.0f}, dark[4] = {0.0f, 0.0f, 0.0f, 0.9f};
    for (int y = 0; y < 256; ++y)
        for (int x = 0; x < 256; ++x)
            if (std::hypot(x - 100.0, y - 128.0) < 60.0) frame.setpixel(x, y, y < 128 ? lit : dark, 4);
    REQUIRE(frame.write(dir + "/frame.exr"));
    OIIO::ImageBuf opaque(OIIO::ImageSpec(256, 256, 3, OIIO::TypeDesc::UINT8));
    REQUIRE(opaque.write(dir + "/opaque.png"));

    checkIsTheDisk(runVfieldCli("silhouette --opacity --threshold 0.5 " + dir + "/frame.exr", dir));

    const Run noAlpha = runVfieldCli("silhouette --opacity " + dir + "/opaque.png", dir);
    CHECK(noAlpha.exitCode != 0);
    CHECK(noAlpha.err.find(dir + "/opaque.png has no alpha channel") != std::string::npos);
    CHECK(lineCount(noAlpha.err) == 1);
    const Run neither = runVfieldCli("silhouette " + dir + "/frame.exr", dir);
    CHECK(neither.exitCode == 2);
    CHECK(lineCount(neither.err) == 1);
}

TEST_CASE("cli: a lone cumulus's displaced surface gives its opacity a fractal outline, as real clouds have", "[cli]")
{
    // scenes/features/cumulus.json at 320x180, frame 2, against a transparent
    // sky: the outline of the pixels the cloud covers by more than half, with
    // its displaced detail, with billows and with the particles' smooth
    // density alone. Its opacity is the density's alone, whatever the light,
    // and each pixel's own samples' (a box filter): the Gaussian's half-pixel
    // softening takes a little off every outline's finest boxes (with it:
    // 1.284, 1.051 and 1.022).
    const std::string dir = vfield::test::scratchDir("cli-cumulus");
    const std::string scene = std::string(VFIELD_SCENES_DIR) + "/features/cumulus.json";
    const auto dimensionOf = [&](const std::string& name, const std::string& sets) {
        const std::string out = dir + "/" + name;
        REQUIRE(
            runVfieldCli(
                "run " + scene + " -o " + out +
                    " --resolution 320x180 --format exr --set /render/transparentSky=true --set /render/pixelFilterWidth=0 -q " +
                    sets,
                dir)
                .exitCode == 0);
        const Run measure = runVfieldCli("silhouette --opacity --threshold 0.5 " + out + "/frame.0002.exr", dir);
        INFO(measure.out);
        const SilhouetteLine line = silhouetteOf(measure);
        CHECK(line.percent > 1.0);
        return line.dimension;
    };
    const double displaced = dimensionOf("displaced", "");
    const double billowed = dimensionOf("billows", "--set '/volume/detail/style=\"billows\"' --set /volume/detail/voxelSize=0.4 "
                                                   "--set /volume/detail/octaves=5 --set /volume/detail/amplitude=2.5 "
                                                   "--set /volume/detail/gain=0.65");
    const double particlesAlone = dimensionOf("plain", "--set /volume/detail/voxelSize=0");
    // Measured 1.302, 1.056 and 1.019. With other seeds of the detail the
    // displaced outline varies by a few hundredths (the coarsest lumps are
    // few, and the outline's largest boxes follow them). Real clouds'
    // outlines measure 1.33 to 1.35 (Lovejoy 1982); the issue asks 1.25 of
    // the showcases.
    CHECK(displaced >= 1.25);
    CHECK(billowed >= particlesAlone + 0.03);
}
