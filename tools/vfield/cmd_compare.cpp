// vfield compare A B: images as idiff compares them, or OpenVDB files voxel by
// voxel, or (--cloud) a cloud's light in a render against a reference.

#include "command.h"

#include <vfield/core/error.h>
#include <vfield/image/cloud_light.h>
#include <vfield/image/grid_compare.h>
#include <vfield/image/image_compare.h>

#include <cstdio>
#include <iostream>

namespace vfield::cli {

namespace {

bool isVdb(const std::string& path) { return path.size() > 4 && path.compare(path.size() - 4, 4, ".vdb") == 0; }

/// Prints the statistics idiff prints; returns the exit status.
int reportImages(const std::string& a, const std::string& b, const ImageCompareOptions& options)
{
    const ImageComparison c = compareImages(a, b, options);
    std::printf("Comparing \"%s\" and \"%s\"\n", a.c_str(), b.c_str());
    if (!c.sizeMismatch.empty()) {
        std::printf("  sizes differ: %s\nFAILURE\n", c.sizeMismatch.c_str());
        return 1;
    }
    std::printf("  Mean error = %.6g\n  RMS error = %.6g\n  Peak SNR = %.6g\n  Max error = %.6g @ (%d, %d, channel %d)\n",
                c.meanError, c.rmsError, c.psnr, c.maxError, c.maxX, c.maxY, c.maxChannel);
    std::printf("  %lld pixels (%.4g%%) over %g\n  %lld pixels (%.4g%%) over %g\n", c.pixelsOverWarn, c.percentOverWarn(),
                options.warnThreshold, c.pixelsOverFail, c.percentOverFail(), options.failThreshold);
    if (!options.diffPath.empty()) std::printf("  difference x %g written to %s\n", options.diffScale, options.diffPath.c_str());
    std::printf("%s\n", c.verdict == CompareVerdict::Pass ? "PASS" : c.verdict == CompareVerdict::Warn ? "WARNING" : "FAILURE");
    return c.verdict == CompareVerdict::Fail ? 1 : 0;
}

/// Prints the cloud's light in `a` against `b`; returns the exit status.
int reportCloudLight(const std::string& a, const std::string& b, const std::string& clear, const CloudLightOptions& options)
{
    const CloudLightComparison c = compareCloudLight(a, b, clear, options);
    std::printf("Comparing the cloud's light in \"%s\" with \"%s\" (without the cloud: \"%s\")\n", a.c_str(), b.c_str(),
                clear.c_str());
    std::printf("  %lld cloud pixels, mean radiance %.6g against %.6g: %.4f (within %g: %s)\n", c.pixels, c.mean, c.referenceMean,
                c.ratio(), options.meanTolerance, c.meansAgree(options) ? "yes" : "no");
    std::printf("  %lld of %lld blocks of %dx%d pixels within %g (%.1f%%, at least %.1f%% wanted)\n", c.blocksWithin, c.blocks,
                options.block, options.block, options.blockTolerance, 100.0 * c.shareWithin(), 100.0 * options.blockShare);
    for (std::size_t i = 0; i < kRmsBlocks.size(); ++i) {
        std::printf("  relative RMS over %lld blocks of %dx%d pixels: %.4f", c.rmsBlocks[i], kRmsBlocks[i], kRmsBlocks[i],
                    c.relativeRms[i]);
        if (options.rmsTolerance[i] >= 0.0)
            std::printf(" (within %g: %s)", options.rmsTolerance[i], c.rmsWithin(options, i) ? "yes" : "no");
        std::printf("\n");
    }
    std::printf("  %lld specks (over 3x3 pixels, more than %g times the reference's light)", c.specks, options.speckRatio);
    if (options.specksAllowed >= 0)
        std::printf(" (at most %lld: %s)", options.specksAllowed, c.specksWithin(options) ? "yes" : "no");
    std::printf("\n");
    const bool agrees = c.agrees(options);
    std::printf("%s\n", agrees ? "PASS" : "FAILURE");
    return agrees ? 0 : 1;
}

int reportGrids(const std::string& a, const std::string& b, double tolerance)
{
    const GridComparison c = compareGridFiles(a, b, tolerance);
    std::printf("Comparing \"%s\" and \"%s\" (tolerance %g)\n", a.c_str(), b.c_str(), tolerance);
    for (const GridDifference& g : c.grids) {
        if (g.comparedByHash)
            std::printf("  %s (%s): %s\n", g.name.c_str(), g.type.c_str(),
                        g.differing ? "contents differ" : "identical contents");
        else
            std::printf("  %s (%s): %llu of %llu voxels differ, max difference %.6g\n", g.name.c_str(), g.type.c_str(),
                        (unsigned long long)g.differing, (unsigned long long)g.voxels, g.maxDifference);
    }
    for (const std::string& name : c.onlyInA) std::printf("  %s: only in %s\n", name.c_str(), a.c_str());
    for (const std::string& name : c.onlyInB) std::printf("  %s: only in %s\n", name.c_str(), b.c_str());
    std::printf("%s\n", c.equal() ? "PASS" : "FAILURE");
    return c.equal() ? 0 : 1;
}

} // namespace

Runner registerCompare(CLI::App& app, const GlobalOptions&)
{
    struct Options {
        std::string a, b;
        ImageCompareOptions image;
        std::string clear; ///< --cloud: the frame without the cloud
        CloudLightOptions light;
        double tolerance = 0.0;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand(
        "compare", "Compare two images as OIIO's idiff does, or two OpenVDB files voxel by voxel, or (--cloud) the "
                   "cloud's light in a render against a reference. Exit 0: pass (or warning), 1: fail, 2: error");
    command->add_option("a", o->a, "First image or .vdb file")->required();
    command->add_option("b", o->b, "Second image or .vdb file")->required();
    command->add_option("--fail", o->image.failThreshold, "Images: a pixel fails when a channel differs by more")
        ->capture_default_str();
    command->add_option("--fail-percent", o->image.failPercent, "Images: % of pixels allowed to fail")
        ->check(CLI::Range(0.0, 100.0))
        ->capture_default_str();
    command->add_option("--hard-fail", o->image.hardFail, "Images: fail if any channel differs by more [default: off]");
    command->add_option("--warn", o->image.warnThreshold, "Images: a pixel warns when a channel differs by more")
        ->capture_default_str();
    command->add_option("--warn-percent", o->image.warnPercent, "Images: % of pixels allowed to warn")
        ->check(CLI::Range(0.0, 100.0))
        ->capture_default_str();
    command->add_option("--diff", o->image.diffPath, "Images: write |A - B| x --diff-scale to this image");
    command->add_option("--diff-scale", o->image.diffScale, "Images: scale of the difference image")->capture_default_str();
    command->add_option("--tolerance", o->tolerance, "VDB files: largest difference of equal voxels")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    command->add_option("--cloud", o->clear,
                        "Light: compare the cloud's light in A (a render) with B (a reference, e.g. --integrator "
                        "reference), both OpenEXR; this is the same frame rendered without the cloud (--set "
                        "/render/extinction=0), which tells the cloud's pixels");
    command->add_option("--block", o->light.block, "Light: side of the blocks compared, pixels")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    command->add_option("--block-tolerance", o->light.blockTolerance, "Light: relative difference a block may have")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    command->add_option("--mean-tolerance", o->light.meanTolerance, "Light: relative difference the means may have")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    command->add_option("--block-share", o->light.blockShare, "Light: share of the whole blocks that must agree")
        ->check(CLI::Range(0.0, 1.0))
        ->capture_default_str();
    command
        ->add_option("--rms-tolerance", o->light.rmsTolerance,
                     "Light: the largest relative RMS over blocks of 4x4 and of 8x8 pixels [default: unchecked]")
        ->check(CLI::NonNegativeNumber)
        ->delimiter(',');
    command
        ->add_option("--specks-allowed", o->light.specksAllowed, "Light: the most specks a render may have [default: unchecked]")
        ->check(CLI::NonNegativeNumber);

    return [o] {
        int status = 0;
        try {
            if (isVdb(o->a) != isVdb(o->b)) throw Error("cannot compare an OpenVDB file with an image");
            if (!o->clear.empty()) status = reportCloudLight(o->a, o->b, o->clear, o->light);
            else status = isVdb(o->a) ? reportGrids(o->a, o->b, o->tolerance) : reportImages(o->a, o->b, o->image);
        } catch (const std::exception& e) {
            std::fflush(stdout);
            throw CommandExit{2, e.what()};
        }
        if (status != 0) throw CommandExit{status, ""};
    };
}

} // namespace vfield::cli
