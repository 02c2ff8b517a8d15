#pragma once
/// @file golden_report.h
/// What a golden check found, as CI systems and people read it: JUnit XML
/// (one test suite, a test case per golden case) and one self-contained HTML
/// page (images embedded, no external scripts or fonts), failures first.

#include <vfield/golden/golden_check.h>

#include <string>
#include <vector>

namespace vfield {

/// Writes JUnit XML to path (atomically). seconds: the whole check's.
void writeJUnitReport(const std::vector<GoldenCaseResult>& results, const std::string& path, double seconds);

/// Writes the HTML report to path (atomically): per case, worst first, its
/// verdict and messages; per image, the golden, the new image and their
/// difference (amplified, its scale stated) with a wipe slider and a flicker
/// toggle between golden and new, and the numbers (mean, max, % of pixels over
/// the threshold).
void writeHtmlReport(const std::vector<GoldenCaseResult>& results, const std::string& path);

} // namespace vfield
