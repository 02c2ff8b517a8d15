#include <vfield/golden/golden_check.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>

namespace fs = std::filesystem;

namespace vfield {

namespace {

GoldenVerdict fromCompare(CompareVerdict verdict)
{
    switch (verdict) {
    case CompareVerdict::Pass:
        return GoldenVerdict::Pass;
    case CompareVerdict::Warn:
        return GoldenVerdict::Warn;
    case CompareVerdict::Fail:
        break;
    }
    return GoldenVerdict::Fail;
}

GoldenImageResult compareImage(const GoldenCase& c, const std::string& image, const std::string& outDir)
{
    GoldenImageResult r;
    r.name = image;
    r.golden = c.goldenPath(image);
    r.output = outDir + "/" + image;
    if (!fs::exists(r.golden)) r.problem = "no golden " + r.golden + " (`vfield golden update` makes it)";
    else if (!fs::exists(r.output)) r.problem = "the commands wrote no " + r.output;
    if (!r.problem.empty()) {
        r.verdict = GoldenVerdict::Fail;
        return r;
    }
    ImageCompareOptions options = c.compare.imageCompareOptions();
    r.difference = outDir + "/" + fs::path(image).stem().string() + ".diff.png";
    options.diffPath = r.difference;
    r.comparison = compareImages(r.golden, r.output, options);
    r.verdict = fromCompare(r.comparison.verdict);
    if (!r.comparison.sizeMismatch.empty()) r.problem = "sizes differ: " + r.comparison.sizeMismatch;
    return r;
}

GoldenGridResult compareGrid(const GoldenCase& c, const GoldenGrid& grid, const std::string& outDir)
{
    GoldenGridResult r;
    r.name = grid.file;
    r.expected = grid.checksum;
    const std::string output = outDir + "/" + grid.file;
    if (!fs::exists(output)) {
        r.problem = "the commands wrote no " + output;
        r.verdict = GoldenVerdict::Fail;
        return r;
    }
    r.actual = vdbFileChecksum(output);
    if (r.actual == r.expected) return r;
    const std::string golden = c.goldenPath(grid.file);
    if (!grid.keepFile || !fs::exists(golden)) {
        r.problem = "checksum " + r.actual + ", the golden's " + r.expected +
                    (grid.keepFile ? " (its kept golden file " + golden + " is missing)" : "");
        r.verdict = GoldenVerdict::Fail;
        return r;
    }
    r.comparedWithFile = true;
    r.comparison = compareGridFiles(golden, output, grid.tolerance);
    if (!r.comparison.equal()) {
        r.verdict = GoldenVerdict::Fail;
        r.problem = "voxels differ from " + golden + " by more than " + std::to_string(grid.tolerance);
    }
    return r;
}

/// A golden replaced whole or not at all.
void copyIntoPlace(const std::string& from, const std::string& to)
{
    writeFileAtomically(
        to, [&](const std::string& temporary) { fs::copy_file(from, temporary, fs::copy_options::overwrite_existing); });
}

} // namespace

const char* goldenVerdictName(GoldenVerdict verdict)
{
    switch (verdict) {
    case GoldenVerdict::Error:
        return "error";
    case GoldenVerdict::Fail:
        return "fail";
    case GoldenVerdict::Warn:
        return "warn";
    case GoldenVerdict::Pass:
        break;
    }
    return "pass";
}

int countVerdicts(const std::vector<GoldenCaseResult>& results, GoldenVerdict verdict)
{
    return int(std::count_if(results.begin(), results.end(), [&](const GoldenCaseResult& r) { return r.verdict == verdict; }));
}

std::string describeImageDifference(const GoldenImageResult& image, const ImageCompareOptions& thresholds)
{
    if (!image.problem.empty()) return image.name + ": " + image.problem;
    const ImageComparison& c = image.comparison;
    char line[320];
    std::snprintf(line, sizeof line, "%s: mean %.3g, max %.3g at (%d, %d), %.3g%% of pixels over %g", image.name.c_str(),
                  c.meanError, c.maxError, c.maxX, c.maxY, c.percentOverFail(), thresholds.failThreshold);
    return line;
}

GoldenCaseResult compareGoldenOutputs(const std::string& name, const GoldenCase& c, const std::string& outDir)
{
    GoldenCaseResult result;
    result.name = name;
    result.goldenCase = c;
    const auto worsen = [&](GoldenVerdict verdict) { result.verdict = std::min(result.verdict, verdict); };
    if (!c.scene.empty()) {
        const std::string hash = fileContentHash(c.scenePath());
        if (hash != c.sceneHash) {
            result.messages.push_back("the scene " + c.scenePath() + " changed since the goldens were made (hash " + hash +
                                      ", recorded " + c.sceneHash + "): check the images, then `vfield golden update`");
            worsen(GoldenVerdict::Fail);
        }
    }
    for (const std::string& image : c.images) {
        GoldenImageResult& r = result.images.emplace_back(compareImage(c, image, outDir));
        worsen(r.verdict);
        if (r.verdict == GoldenVerdict::Fail)
            result.messages.push_back(describeImageDifference(r, c.compare.imageCompareOptions()));
    }
    for (const GoldenGrid& grid : c.grids) {
        GoldenGridResult& r = result.grids.emplace_back(compareGrid(c, grid, outDir));
        worsen(r.verdict);
        if (r.verdict == GoldenVerdict::Fail) result.messages.push_back(r.name + ": " + r.problem);
    }
    return result;
}

void acceptGoldenOutputs(GoldenCase& c, const std::string& outDir, const std::string& date, const std::string& reason)
{
    GoldenRegeneration entry{date, reason, {}};
    for (const std::string& image : c.images) {
        const std::string output = outDir + "/" + image;
        if (!fs::exists(output)) throw FileError(output, "no such output (the case's commands did not write it)");
        const std::string golden = c.goldenPath(image);
        if (fs::exists(golden)) {
            GoldenImageResult old;
            old.name = fs::path(image).filename().string();
            old.comparison = compareImages(golden, output, c.compare.imageCompareOptions());
            if (!old.comparison.sizeMismatch.empty()) old.problem = "sizes differ: " + old.comparison.sizeMismatch;
            entry.differences.push_back(describeImageDifference(old, c.compare.imageCompareOptions()));
        }
        copyIntoPlace(output, golden);
    }
    for (GoldenGrid& grid : c.grids) {
        const std::string output = outDir + "/" + grid.file;
        if (!fs::exists(output)) throw FileError(output, "no such output (the case's commands did not write it)");
        const std::string checksum = vdbFileChecksum(output);
        if (!grid.checksum.empty() && checksum != grid.checksum)
            entry.differences.push_back(grid.file + ": checksum " + grid.checksum + " -> " + checksum);
        grid.checksum = checksum;
        if (grid.keepFile) copyIntoPlace(output, c.goldenPath(grid.file));
    }
    if (!c.scene.empty()) c.sceneHash = fileContentHash(c.scenePath());
    c.regenerated.push_back(entry);
    writeGoldenCase(c);
}

} // namespace vfield
