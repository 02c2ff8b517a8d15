#pragma once
/// @file golden_check.h
/// A golden case's outputs compared with its goldens, and accepted as its new
/// goldens on purpose. Running the case's commands is the caller's (the
/// `vfield golden` command runs them); this compares and records.

#include <vfield/golden/golden_case.h>
#include <vfield/image/grid_compare.h>
#include <vfield/image/image_compare.h>

#include <string>
#include <vector>

namespace vfield {

/// Worst first: a case's verdict is its worst output's. Warn passes.
enum class GoldenVerdict { Error, Fail, Warn, Pass };
const char* goldenVerdictName(GoldenVerdict verdict); ///< "error", "fail", "warn", "pass"

struct GoldenImageResult {
    std::string name;                       ///< the output, relative to the outputs' folder
    std::string golden, output, difference; ///< paths; difference: |golden - output| x the case's diffScale (PNG)
    GoldenVerdict verdict = GoldenVerdict::Pass;
    ImageComparison comparison;
    std::string problem; ///< why it could not be compared (no golden, no output), or empty
};

struct GoldenGridResult {
    std::string name;
    std::string expected, actual; ///< checksums
    GoldenVerdict verdict = GoldenVerdict::Pass;
    bool comparedWithFile = false; ///< the checksums differed and the kept golden file was compared
    GridComparison comparison;     ///< when comparedWithFile
    std::string problem;
};

struct GoldenCaseResult {
    std::string name;
    GoldenCase goldenCase;
    GoldenVerdict verdict = GoldenVerdict::Pass;
    std::vector<std::string> messages; ///< what made it fail or err, one line each
    std::vector<GoldenImageResult> images;
    std::vector<GoldenGridResult> grids;
    double seconds = 0.0; ///< running its commands and comparing
};

/// How many of the results have the verdict.
int countVerdicts(const std::vector<GoldenCaseResult>& results, GoldenVerdict verdict);

/// Compares the outputs in outDir with c's goldens; writes the difference
/// images into outDir. A scene whose content changed since the goldens were
/// made fails the case. Throws only when an output exists but cannot be read.
GoldenCaseResult compareGoldenOutputs(const std::string& name, const GoldenCase& c, const std::string& outDir);

/// Makes the outputs in outDir c's goldens: copies images and kept grid files
/// beside case.json, records the grids' checksums and the scene's hash, and
/// appends {date, reason, how each output differs from its old golden} to
/// c.regenerated. Writes case.json. Throws FileError when an output is missing.
void acceptGoldenOutputs(GoldenCase& c, const std::string& outDir, const std::string& date, const std::string& reason);

/// One line: "frame.0120.png: mean 0.0012, max 0.047 at (10, 20), 0.14% of pixels over 0.004".
std::string describeImageDifference(const GoldenImageResult& image, const ImageCompareOptions& thresholds);

} // namespace vfield
