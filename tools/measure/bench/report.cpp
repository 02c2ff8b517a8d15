// vfield_bench_report BENCH.json: the Markdown tables of tools/measure/bench/run from
// Google Benchmark's JSON output (run with repetitions): each figure's median,
// min and max over the repetitions, its ratio to its baseline and its target,
// the scaling of each stage, and the machine.

#include "showcase_samples.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <string>
#include <vector>

namespace {

/// Repetitions of one benchmark: a value per repetition.
struct Samples {
    std::vector<double> values;
    double median() const
    {
        std::vector<double> v = values;
        std::sort(v.begin(), v.end());
        const std::size_t n = v.size();
        return n == 0 ? 0.0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    }
    double min() const { return values.empty() ? 0.0 : *std::min_element(values.begin(), values.end()); }
    double max() const { return values.empty() ? 0.0 : *std::max_element(values.begin(), values.end()); }
};

class Results {
public:
    explicit Results(const nlohmann::json& json)
    {
        for (const nlohmann::json& b : json.at("benchmarks")) {
            if (b.value("run_type", "") != "iteration" || b.contains("error_occurred")) continue;
            std::string name = b.at("run_name").get<std::string>();
            for (const char* noise : {"/real_time", "/iterations:1"})
                for (std::size_t at; (at = name.find(noise)) != std::string::npos;) name.erase(at, std::string(noise).size());
            mTimes[name].values.push_back(toMilliseconds(b.at("real_time").get<double>(), b.at("time_unit").get<std::string>()));
            for (const auto& [key, value] : b.items())
                if (value.is_number()) mCounters[name + "#" + key].values.push_back(value.get<double>());
        }
    }

    /// Milliseconds per iteration; throws if the benchmark did not run.
    const Samples& time(const std::string& name) const { return get(mTimes, name); }
    const Samples& counter(const std::string& name, const std::string& key) const { return get(mCounters, name + "#" + key); }
    bool has(const std::string& name) const { return mTimes.count(name) > 0; }

private:
    static double toMilliseconds(double value, const std::string& unit)
    {
        return unit == "ns" ? value * 1e-6 : unit == "us" ? value * 1e-3 : unit == "s" ? value * 1e3 : value;
    }
    static const Samples& get(const std::map<std::string, Samples>& map, const std::string& name)
    {
        const auto found = map.find(name);
        if (found == map.end()) throw std::runtime_error("no results of " + name);
        return found->second;
    }
    std::map<std::string, Samples> mTimes, mCounters;
};

std::string format(const char* pattern, double value)
{
    char text[64];
    std::snprintf(text, sizeof text, pattern, value);
    return text;
}

/// "median (min-max) unit" with the pattern's precision.
std::string spread(const Samples& s, const char* pattern, const std::string& unit, double scale = 1.0)
{
    return format(pattern, s.median() * scale) + " (" + format(pattern, s.min() * scale) + "-" +
           format(pattern, s.max() * scale) + ") " + unit;
}

void row(const std::vector<std::string>& cells)
{
    std::string line = "|";
    for (const std::string& cell : cells) line += " " + cell + " |";
    std::cout << line << "\n";
}

std::string verdict(bool met) { return met ? "met" : "**missed**"; }

} // namespace

int main(int argc, char** argv)
{
    if (argc != 2) {
        std::cerr << "usage: vfield_bench_report BENCH.json\n";
        return 2;
    }
    nlohmann::json json;
    try {
        std::ifstream in(argv[1]);
        json = nlohmann::json::parse(in);
        const Results r(json);
        const nlohmann::json& context = json.at("context");
        std::cout << "Machine: " << context.value("host_name", "?") << ", " << context.value("num_cpus", 0) << " CPUs at "
                  << context.value("mhz_per_cpu", 0) << " MHz; " << context.value("date", "") << ". Medians over "
                  << r.time("BM_OctreeBuild/100000").values.size() << " repetitions, (min-max).\n\n";

        row({"stage", "vfield", "baseline", "ratio", "target", ""});
        row({"---", "---", "---", "---", "---", "---"});
        for (const auto& [size, label] :
             std::vector<std::pair<std::string, std::string>>{{"100000", "100k"}, {"1000000", "1M"}}) {
            const std::string name = "BM_OctreeBuild/" + size;
            const double rate = r.counter(name, "items_per_second").median();
            row({"octree build, " + label + " triangles", spread(r.time(name), "%.1f", "ms"), "",
                 format("%.2f", rate / 1e6) + " M triangles/s", ">= 2 M/s", verdict(rate >= 2e6)});
        }
        for (const char* threads : {"1", "2"}) {
            const std::string name = std::string("BM_PointQueries/threads:") + threads;
            row({std::string("point queries, ") + threads + " thread(s)",
                 spread(r.counter(name, "items_per_second"), "%.1f", "M/s", 1e-6), "", "", "", ""});
        }
        row({"voxelize the 1M-triangle field", spread(r.time("BM_Voxelize/1000000"), "%.1f", "ms"), "", "", "", ""});
        for (const auto& [particles, threads] :
             std::vector<std::pair<std::string, std::string>>{{"1000000", "1"}, {"1000000", "2"}}) {
            const std::string ours = "BM_CloudFrame/particles:" + particles + "/threads:" + threads;
            const std::string raw = "BM_RawSamplerAdvection/particles:" + particles + "/threads:" + threads;
            const Samples& rate = r.counter(ours, "particle_steps_per_s");
            const double ratio = rate.median() / r.counter(raw, "particle_steps_per_s").median();
            // One substep of every particle: the frame's time over its mean substeps per particle.
            const double substepMs = std::stod(particles) / rate.median() * 1e3;
            row({"the main job's advection, 1M particles, " + threads + " thread(s)",
                 spread(rate, "%.1f", "M steps/s", 1e-6) + "; " + format("%.2f", substepMs) + " ms a substep",
                 spread(r.counter(raw, "particle_steps_per_s"), "%.1f", "M steps/s", 1e-6) + " raw trilinear sampler",
                 format("%.2f", ratio), ">= 0.7", verdict(ratio >= 0.7)});
        }
        // The splat and the volume stage against OpenVDB's rasterizer on the same 1M particles.
        const Samples& rawSplat = r.time("BM_RawOpenVdbSplat/particles:1000000/detailVoxel:0");
        const std::string rawSplatText = spread(rawSplat, "%.0f", "ms") + " raw OpenVDB splat (FrustumRasterizer, splat voxel)";
        const Samples& splat = r.time("BM_DensitySplat/particles:1000000");
        row({"the main job's density splat, 1M particles (no detail)", spread(splat, "%.0f", "ms"), rawSplatText,
             format("%.2f", splat.median() / rawSplat.median()) + "x the raw", "<= 1x",
             verdict(splat.median() <= rawSplat.median())});
        const std::string stageName = "BM_VolumeStage/particles:1000000";
        const Samples& stage = r.time(stageName);
        const double stageRatio = stage.median() / rawSplat.median();
        const auto part = [&](const char* counter) { return format("%.0f", r.counter(stageName, counter).median() * 1e3); };
        row({"the main job's volume stage, 1M particles (splat + detail + cutoff + write)",
             spread(stage, "%.0f", "ms") + ": splat " + part("splat_s") + ", detail " + part("detail_s") + ", write " +
                 part("write_s"),
             rawSplatText + "; " + spread(r.time("BM_RawOpenVdbSplat/particles:1000000/detailVoxel:1"), "%.0f", "ms") +
                 " at the detail's voxel",
             format("%.2f", stageRatio) + "x the raw", "<= 2x", verdict(stageRatio <= 2.0)});
        // The target holds at the showcase's own samples per pixel, over
        // which a pixel's shading noise is shared; one sample a pixel is shown.
        const std::string sceneSpp = std::to_string(vfield::bench::kShowcaseSamplesPerPixel);
        for (const std::string& spp : {std::string("1"), sceneSpp})
            for (const auto& [w, h] : std::vector<std::pair<std::string, std::string>>{{"640", "360"}, {"1280", "720"}}) {
                const std::string size = "w:" + w + "/h:" + h + "/spp:" + spp;
                const Samples& ours = r.time("BM_RenderSurfaces/" + size);
                const Samples& raw = r.time("BM_RawEmbreeRays/" + size + "/packets:0");
                const Samples& rawPackets = r.time("BM_RawEmbreeRays/" + size + "/packets:1");
                // The target is against raw packets, as vfield traces and
                // raw Embree users do; rays one at a time are shown beside it.
                const double ratio = rawPackets.median() / ours.median();
                const bool targeted = spp == sceneSpp && w == "1280";
                row({"surfaces-only frame " + w + "x" + h + ", " + spp + " spp" + (spp == sceneSpp ? " (the scene's)" : ""),
                     spread(ours, "%.1f", "ms"),
                     spread(rawPackets, "%.1f", "ms") + " raw Embree in 8-wide packets (primary + shadow a sample); " +
                         spread(raw, "%.1f", "ms") + " a ray at a time",
                     format("%.2f", ratio) + " of packets; " + format("%.2f", raw.median() / ours.median()) + " of single rays",
                     targeted ? ">= 0.7 of packets" : "", targeted ? verdict(ratio >= 0.7) : ""});
            }
        const Samples& cloud = r.time("BM_RenderCloud/w:640/h:360/spp:1/skip:1");
        row({"cloud frame 640x360, 1 spp", spread(cloud, "%.0f", "ms"), "", "", "<= 300 ms", verdict(cloud.median() <= 300.0)});
        const Samples& paths = r.time("BM_RenderCloudPaths/w:640/h:360/spp:1");
        row({"cloud frame 640x360, 1 spp, multiple scattering by paths", spread(paths, "%.0f", "ms"), "", "", "<= 300 ms",
             verdict(paths.median() <= 300.0)});
        if (r.has("BM_PovrayFrame/w:320/h:180/spp:1")) {
            const Samples& pov = r.time("BM_PovrayFrame/w:320/h:180/spp:1");
            const Samples& ours = r.time("BM_RenderCloud/w:320/h:180/spp:1/skip:1");
            const double ratio = pov.median() / ours.median();
            row({"cloud frame 320x180, 1 spp", spread(ours, "%.1f", "ms"), spread(pov, "%.0f", "ms") + " POV-Ray back-end",
                 format("%.0f", ratio) + "x faster", ">= 20x", verdict(ratio >= 20.0)});
        }

        std::cout
            << "\nScaling: the input doubled three times; each step's cost ratio (n log n gives a little over 2, linear 2).\n\n";
        row({"stage", "sizes", "median times", "growth per doubling"});
        row({"---", "---", "---", "---"});
        const auto scaling = [&](const std::string& stage, const std::vector<std::string>& names, const std::string& sizes) {
            std::string times, growth;
            for (std::size_t i = 0; i < names.size(); ++i) {
                const double t = r.time(names[i]).median();
                times += (i ? " / " : "") + format(t < 10 ? "%.2f" : "%.1f", t);
                if (i) growth += (i > 1 ? ", " : "") + format("x%.2f", t / r.time(names[i - 1]).median());
            }
            row({stage, sizes, times + " ms", growth});
        };
        scaling("octree build",
                {"BM_OctreeBuild/100000", "BM_OctreeBuild/200000", "BM_OctreeBuild/400000", "BM_OctreeBuild/800000"},
                "100k-800k triangles");
        scaling("the main job's advection (a frame, 2 threads)",
                {"BM_CloudFrame/particles:125000/threads:2", "BM_CloudFrame/particles:250000/threads:2",
                 "BM_CloudFrame/particles:500000/threads:2", "BM_CloudFrame/particles:1000000/threads:2"},
                "125k-1M particles");
        scaling("the main job's density splat (no detail)",
                {"BM_DensitySplat/particles:125000", "BM_DensitySplat/particles:250000", "BM_DensitySplat/particles:500000",
                 "BM_DensitySplat/particles:1000000"},
                "125k-1M particles");
        const auto mainJob = [](const std::string& benchmark) {
            std::vector<std::string> names;
            for (const char* particles : {"125000", "250000", "500000", "1000000"})
                names.push_back(benchmark + "/particles:" + particles);
            return names;
        };
        scaling("the main job's volume stage (splat, detail, write; frame 120)", mainJob("BM_VolumeStage"), "125k-1M particles");
        scaling("the main job's clearance (frame 120)", mainJob("BM_Clearance"), "125k-1M particles");
        scaling("the main job's frame 120 rendered, 640x360, 1 spp", mainJob("BM_RenderMainJob"), "125k-1M particles");
        scaling("surfaces-only frame",
                {"BM_RenderSurfaces/w:320/h:180/spp:1", "BM_RenderSurfaces/w:452/h:254/spp:1",
                 "BM_RenderSurfaces/w:640/h:360/spp:1", "BM_RenderSurfaces/w:905/h:509/spp:1"},
                "320x180-905x509 pixels");
        scaling("surfaces-only frame, to full HD",
                {"BM_RenderSurfaces/w:640/h:360/spp:1", "BM_RenderSurfaces/w:1280/h:720/spp:1",
                 "BM_RenderSurfaces/w:1920/h:1080/spp:1"},
                "640x360-1920x1080 (pixels x4, x2.25)");
        scaling("cloud frame, 1 spp",
                {"BM_RenderCloud/w:320/h:180/spp:1/skip:1", "BM_RenderCloud/w:640/h:360/spp:1/skip:1",
                 "BM_RenderCloud/w:1280/h:720/spp:1/skip:1", "BM_RenderCloud/w:1920/h:1080/spp:1/skip:1"},
                "320x180-1920x1080 (pixels x4, x4, x2.25)");
    } catch (const std::exception& e) {
        std::cerr << "vfield_bench_report: " << argv[1] << ": " << e.what() << "\n";
        return 1;
    }
    return 0;
}
