// vfield metrics SIM...: what a simulation folder shows about its guarantees,
// its motion and its cost (run_metrics.h), one run per folder; --markdown
// prints one table row per run, as tools/measure/compare-methods collects them.

#include "command.h"

#include <vfield/run/run_metrics.h>

#include <cstdio>
#include <string>
#include <vector>

namespace vfield::cli {

namespace {

std::string format(const char* pattern, double value)
{
    char text[64];
    std::snprintf(text, sizeof text, pattern, value);
    return text;
}

std::string methods(const RunMetrics& m)
{
    std::string out;
    for (const FieldRecord& f : m.fields) out += (out.empty() ? "" : ", ") + f.object + ": " + f.method;
    return out.empty() ? "none" : out;
}

double buildSeconds(const RunMetrics& m)
{
    double total = 0.0;
    for (const FieldRecord& f : m.fields) total += f.buildSeconds;
    return total;
}

double memoryMegabytes(const RunMetrics& m)
{
    double total = 0.0;
    for (const FieldRecord& f : m.fields) total += double(f.memoryBytes);
    return total / (1024.0 * 1024.0);
}

/// The dynamic objects' figures: the worst of each over all of them.
struct ObjectSummary {
    double minClearance = 0.0, meanJerk = 0.0, peakJerk = 0.0, stallSeconds = 0.0;
    bool exact = true;
};

ObjectSummary summarizeObjects(const RunMetrics& m)
{
    ObjectSummary s;
    for (std::size_t i = 0; i < m.objects.size(); ++i) {
        const ObjectMotion& o = m.objects[i];
        if (i == 0 || o.minClearance < s.minClearance) {
            s.minClearance = o.minClearance;
            s.exact = o.clearanceExact;
        }
        s.meanJerk = std::max(s.meanJerk, o.meanJerk);
        s.peakJerk = std::max(s.peakJerk, o.peakJerk);
        s.stallSeconds += o.stallSeconds;
    }
    return s;
}

void printMarkdownHeader()
{
    std::printf("| run | fields | build s | field MiB | simulate s | substeps / particle-frame | particle penetrations | "
                "particle clearance min / mean | path curvature rad/unit | trapped particles | object clearance min | "
                "object jerk mean / peak | stalls s |\n");
    std::printf("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
}

void printMarkdownRow(const RunMetrics& m)
{
    const bool particles = m.particles > 0;
    const ObjectSummary o = summarizeObjects(m);
    const std::string none = "-";
    const std::string row[] = {
        m.folder,
        methods(m),
        format("%.2f", buildSeconds(m)),
        format("%.1f", memoryMegabytes(m)),
        format("%.1f", m.simulateSeconds),
        particles ? format("%.2f", m.substepsPerParticleFrame) : none,
        particles ? std::to_string(m.penetrations) : none,
        particles ? format("%.2f", m.minClearance) + " / " + format("%.1f", m.meanClearance) : none,
        particles ? format("%.4f", m.meanCurvature) : none,
        particles ? std::to_string(m.trapped) : none,
        m.objects.empty() ? none : (o.exact ? "" : "> ") + format("%.2f", o.minClearance),
        m.objects.empty() ? none : format("%.0f", o.meanJerk) + " / " + format("%.0f", o.peakJerk),
        m.objects.empty() ? none : format("%.1f", o.stallSeconds),
    };
    std::string line = "|";
    for (const std::string& cell : row) line += " " + cell + " |";
    std::printf("%s\n", line.c_str());
}

void printPlain(const RunMetrics& m)
{
    std::printf("%s: %d frames, fields %s (built in %.2f s, %.1f MiB), simulated in %.1f s\n", m.folder.c_str(), m.frames,
                methods(m).c_str(), buildSeconds(m), memoryMegabytes(m), m.simulateSeconds);
    if (m.particles > 0)
        std::printf("  particles: %llu, %.2f substeps per particle-frame, %llu penetrations, clearance min %.3g mean %.3g, "
                    "path curvature %.4g rad/unit, %llu trapped\n",
                    (unsigned long long)m.particles, m.substepsPerParticleFrame, (unsigned long long)m.penetrations,
                    m.minClearance, m.meanClearance, m.meanCurvature, (unsigned long long)m.trapped);
    if (m.cloudLength > 0.0)
        std::printf("  cloud over the second half: its centroid at (%.4g, %.4g, %.4g) wandered %.3g units, %.3g of its length "
                    "%.3g along its particles' motion, their median speed %.3g units/s\n",
                    m.meanCentroid[0], m.meanCentroid[1], m.meanCentroid[2], m.centroidWander, m.centroidWander / m.cloudLength,
                    m.cloudLength, m.medianSpeed);
    for (const ObjectMotion& o : m.objects)
        std::printf("  %s: cruise %.3g units/s, jerk mean %.4g peak %.4g units/s^3, stalled %.3g s, clearance %s%.3g\n",
                    o.name.c_str(), o.cruiseSpeed, o.meanJerk, o.peakJerk, o.stallSeconds, o.clearanceExact ? "" : "at least ",
                    o.minClearance);
}

} // namespace

Runner registerMetrics(CLI::App& app, const GlobalOptions&)
{
    struct Options {
        std::vector<std::string> folders;
        bool markdown = false;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand("metrics", "Measure simulation folders: guarantees, smoothness, stalls and cost");
    command->add_option("folders", o->folders, "Simulation folders (vfield simulate -o)")->required();
    command->add_flag("--markdown", o->markdown, "Print a Markdown table, a row per folder");

    return [o] {
        std::vector<RunMetrics> runs;
        for (const std::string& folder : o->folders) runs.push_back(measureRun(folder));
        if (o->markdown) printMarkdownHeader();
        for (const RunMetrics& m : runs) o->markdown ? printMarkdownRow(m) : printPlain(m);
    };
}

} // namespace vfield::cli
