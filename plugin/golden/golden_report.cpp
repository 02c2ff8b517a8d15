#include <vfield/golden/golden_report.h>

#include <vfield/core/atomic_file.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>

namespace fs = std::filesystem;

namespace vfield {

namespace {

/// Text safe inside XML and HTML elements and attribute values.
std::string escaped(const std::string& text)
{
    std::string out;
    for (const char c : text) {
        switch (c) {
        case '&':
            out += "&amp;";
            break;
        case '<':
            out += "&lt;";
            break;
        case '>':
            out += "&gt;";
            break;
        case '"':
            out += "&quot;";
            break;
        default:
            out += c;
        }
    }
    return out;
}

std::string formatted(const char* format, double value)
{
    char text[64];
    std::snprintf(text, sizeof text, format, value);
    return text;
}

/// The results worst first, in their order within a verdict.
std::vector<const GoldenCaseResult*> worstFirst(const std::vector<GoldenCaseResult>& results)
{
    std::vector<const GoldenCaseResult*> ordered;
    for (const GoldenCaseResult& r : results) ordered.push_back(&r);
    std::stable_sort(ordered.begin(), ordered.end(),
                     [](const GoldenCaseResult* a, const GoldenCaseResult* b) { return a->verdict < b->verdict; });
    return ordered;
}

std::string base64(const std::string& bytes)
{
    static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
        uint32_t word = uint32_t(uint8_t(bytes[i])) << 16;
        if (n > 1) word |= uint32_t(uint8_t(bytes[i + 1])) << 8;
        if (n > 2) word |= uint32_t(uint8_t(bytes[i + 2]));
        for (std::size_t k = 0; k < 4; ++k) out += k <= n ? digits[(word >> (18 - 6 * k)) & 63] : '=';
    }
    return out;
}

/// An <img> holding the PNG itself, so that the page works wherever it is copied.
std::string embeddedImage(const std::string& path, const std::string& attributes)
{
    std::error_code error;
    if (path.empty() || !fs::exists(path, error)) return "<div class=\"missing\">(none)</div>";
    if (fs::path(path).extension() != ".png")
        return "<div class=\"missing\">" + escaped(fs::path(path).filename().string()) + "</div>";
    return "<img " + attributes + " alt=\"" + escaped(fs::path(path).filename().string()) + "\" src=\"data:image/png;base64," +
           base64(readFileBytes(path)) + "\">";
}

const char* kStyle = R"(
body { font: 14px/1.4 sans-serif; background: #202124; color: #e8eaed; margin: 20px; }
h1 { font-size: 20px; } h2 { font-size: 17px; margin: 0 0 6px; } h3 { font-size: 14px; margin: 12px 0 4px; }
.case { border-left: 6px solid #5f6368; background: #2b2c2f; padding: 10px 14px; margin: 0 0 18px; }
.case.error, .case.fail { border-color: #ea4335; } .case.warn { border-color: #fbbc04; } .case.pass { border-color: #34a853; }
.verdict { display: inline-block; min-width: 44px; padding: 1px 6px; margin-right: 8px; border-radius: 3px; font-weight: bold;
  text-align: center; color: #202124; }
.error .verdict, .fail .verdict, .verdict.fail { background: #ea4335; } .warn .verdict, .verdict.warn { background: #fbbc04; }
.pass .verdict, .verdict.pass { background: #34a853; }
.why { color: #9aa0a6; max-width: 70em; } .messages { color: #f28b82; }
figure { display: inline-block; vertical-align: top; margin: 0 12px 8px 0; }
figcaption { color: #9aa0a6; font-size: 12px; }
img { display: block; image-rendering: pixelated; max-width: 45vw; height: auto; }
.wipe { position: relative; display: inline-block; }
.wipe img.over { position: absolute; left: 0; top: 0; clip-path: inset(0 50% 0 0); }
.wipe input { display: block; width: 100%; margin: 4px 0 0; }
table { border-collapse: collapse; margin: 4px 0; } td, th { padding: 1px 10px 1px 0; text-align: left; font-size: 13px; }
.missing { padding: 20px; color: #9aa0a6; border: 1px dashed #5f6368; }
)";

// The wipe's top image is the golden, clipped at the slider; the flicker
// button swaps which of the two is shown. Both read the figures' own images,
// so each image is embedded once.
const char* kScript = R"(
document.querySelectorAll('.wipe').forEach(function (wipe) {
  var golden = document.getElementById(wipe.dataset.golden), fresh = document.getElementById(wipe.dataset.fresh);
  var under = wipe.querySelector('img.under'), over = wipe.querySelector('img.over');
  under.src = fresh.src; over.src = golden.src;
  var slider = wipe.querySelector('input');
  slider.addEventListener('input', function () { over.style.clipPath = 'inset(0 ' + (100 - slider.value) + '% 0 0)'; });
  var timer = null, button = wipe.parentNode.querySelector('button');
  button.addEventListener('click', function () {
    if (timer) { clearInterval(timer); timer = null; over.style.visibility = 'visible'; button.textContent = 'flicker'; return; }
    over.style.clipPath = 'none';
    timer = setInterval(function () { over.style.visibility = over.style.visibility === 'hidden' ? 'visible' : 'hidden'; }, 500);
    button.textContent = 'stop';
  });
});
)";

std::string imageSection(const GoldenImageResult& image, const ImageCompareOptions& thresholds, const std::string& id)
{
    std::string html = "<div class=\"image\"><h3><span class=\"verdict " + std::string(goldenVerdictName(image.verdict)) + "\">" +
                       goldenVerdictName(image.verdict) + "</span>" + escaped(image.name) + "</h3>\n";
    if (!image.problem.empty()) html += "<p class=\"messages\">" + escaped(image.problem) + "</p>\n";
    if (image.comparison.pixels > 0) {
        const ImageComparison& c = image.comparison;
        html += "<table><tr><th>mean</th><th>max</th><th>pixels over " + formatted("%g", thresholds.failThreshold) +
                " (fail)</th><th>over " + formatted("%g", thresholds.warnThreshold) + " (warn)</th><th>PSNR</th></tr><tr><td>" +
                formatted("%.4g", c.meanError) + "</td><td>" + formatted("%.4g", c.maxError) + " at (" + std::to_string(c.maxX) +
                ", " + std::to_string(c.maxY) + ")</td><td>" + formatted("%.3g%%", c.percentOverFail()) + " (allowed " +
                formatted("%g%%", thresholds.failPercent) + ")</td><td>" + formatted("%.3g%%", c.percentOverWarn()) +
                "</td><td>" + formatted("%.1f dB", c.psnr) + "</td></tr></table>\n";
    }
    html += "<figure><figcaption>golden</figcaption>" + embeddedImage(image.golden, "id=\"" + id + "-golden\"") + "</figure>";
    html += "<figure><figcaption>new</figcaption>" + embeddedImage(image.output, "id=\"" + id + "-new\"") + "</figure>";
    html += "<figure><figcaption>difference &times; " + formatted("%g", thresholds.diffScale) + "</figcaption>" +
            embeddedImage(image.difference, "") + "</figure>";
    if (image.comparison.pixels > 0 && image.comparison.sizeMismatch.empty())
        html += "<figure><figcaption>golden (left of the slider) | new</figcaption><div class=\"wipe\" data-golden=\"" + id +
                "-golden\" data-fresh=\"" + id +
                "-new\"><img class=\"under\" alt=\"new\"><img class=\"over\" alt=\"golden\"><input type=\"range\" min=\"0\" "
                "max=\"100\" value=\"50\" aria-label=\"wipe\"></div><button type=\"button\">flicker</button></figure>";
    return html + "</div>\n";
}

std::string gridRows(const GoldenCaseResult& r)
{
    if (r.grids.empty()) return "";
    std::string html = "<h3>grids</h3><table><tr><th></th><th>file</th><th>checksum</th><th>golden</th><th></th></tr>\n";
    for (const GoldenGridResult& g : r.grids) {
        std::string detail = escaped(g.problem);
        if (g.comparedWithFile)
            for (const GridDifference& d : g.comparison.grids)
                detail += " " + escaped(d.name) + ": " + std::to_string(d.differing) + " of " + std::to_string(d.voxels) +
                          " voxels differ (max " + formatted("%.3g", d.maxDifference) + ").";
        html += "<tr><td><span class=\"verdict " + std::string(goldenVerdictName(g.verdict)) + "\">" +
                goldenVerdictName(g.verdict) + "</span></td><td>" + escaped(g.name) + "</td><td>" + escaped(g.actual) +
                "</td><td>" + escaped(g.expected) + "</td><td>" + detail + "</td></tr>\n";
    }
    return html + "</table>\n";
}

} // namespace

void writeJUnitReport(const std::vector<GoldenCaseResult>& results, const std::string& path, double seconds)
{
    const int failures = countVerdicts(results, GoldenVerdict::Fail), errors = countVerdicts(results, GoldenVerdict::Error);
    const std::string counts = "tests=\"" + std::to_string(results.size()) + "\" failures=\"" + std::to_string(failures) +
                               "\" errors=\"" + std::to_string(errors) + "\" time=\"" + formatted("%.3f", seconds) + "\"";
    std::string xml = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites name=\"vfield golden\" " + counts +
                      ">\n  <testsuite name=\"vfield golden\" " + counts + ">\n";
    for (const GoldenCaseResult& r : results) {
        xml +=
            "    <testcase classname=\"golden\" name=\"" + escaped(r.name) + "\" time=\"" + formatted("%.3f", r.seconds) + "\"";
        std::string details;
        for (const std::string& message : r.messages) details += message + "\n";
        std::string output;
        for (const GoldenImageResult& image : r.images)
            output += describeImageDifference(image, r.goldenCase.compare.imageCompareOptions()) + "\n";
        for (const GoldenGridResult& grid : r.grids)
            output += grid.name + ": checksum " + grid.actual + (grid.problem.empty() ? "" : ", " + grid.problem) + "\n";
        xml += ">\n";
        if (r.verdict == GoldenVerdict::Fail || r.verdict == GoldenVerdict::Error) {
            const char* element = r.verdict == GoldenVerdict::Fail ? "failure" : "error";
            const std::string first = r.messages.empty() ? std::string(element) : r.messages.front();
            xml += "      <" + std::string(element) + " type=\"golden\" message=\"" + escaped(first) + "\">" + escaped(details) +
                   "</" + element + ">\n";
        }
        xml += "      <system-out>" + escaped(output) + "</system-out>\n    </testcase>\n";
    }
    xml += "  </testsuite>\n</testsuites>\n";
    writeTextAtomically(path, xml);
}

void writeHtmlReport(const std::vector<GoldenCaseResult>& results, const std::string& path)
{
    const int failing = countVerdicts(results, GoldenVerdict::Fail) + countVerdicts(results, GoldenVerdict::Error);
    const std::string title = "vfield golden check: " + std::to_string(failing) + " failed, " +
                              std::to_string(int(results.size()) - failing) + " passed";
    std::string html = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" + escaped(title) +
                       "</title>\n<style>" + kStyle + "</style></head>\n<body>\n<h1>" + escaped(title) + "</h1>\n";
    int index = 0;
    for (const GoldenCaseResult* r : worstFirst(results)) {
        const std::string verdict = goldenVerdictName(r->verdict);
        html += "<section class=\"case " + verdict + "\" data-verdict=\"" + verdict + "\" data-name=\"" + escaped(r->name) +
                "\">\n<h2><span class=\"verdict\">" + verdict + "</span>" + escaped(r->name) + "</h2>\n";
        if (!r->goldenCase.why.empty()) html += "<p class=\"why\">" + escaped(r->goldenCase.why) + "</p>\n";
        if (!r->messages.empty()) {
            html += "<ul class=\"messages\">";
            for (const std::string& message : r->messages) html += "<li>" + escaped(message) + "</li>";
            html += "</ul>\n";
        }
        for (const GoldenImageResult& image : r->images)
            html += imageSection(image, r->goldenCase.compare.imageCompareOptions(), "image-" + std::to_string(index++));
        html += gridRows(*r) + "</section>\n";
    }
    html += "<script>" + std::string(kScript) + "</script>\n</body></html>\n";
    writeTextAtomically(path, html);
}

} // namespace vfield
