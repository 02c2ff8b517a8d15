#include <vfield/scene/simulation_run.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>
#include <vfield/core/vdb_file.h>
#include <vfield/volume/density_splat.h>
#include <vfield/volume/particle_grid.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace vfield {

std::string frameFileName(const std::string& stem, int frame, const std::string& extension)
{
    char name[256];
    std::snprintf(name, sizeof name, "%s.%04d.%s", stem.c_str(), frame, extension.c_str());
    return name;
}

namespace {

nlohmann::json toJson(const ClearanceStats& c)
{
    if (c.samples == 0) return nullptr;
    return {{"min", c.minimum}, {"p01", c.percentile1}, {"penetrations", c.penetrations}, {"samples", c.samples}};
}

ClearanceStats clearanceFromJson(const nlohmann::json& j)
{
    ClearanceStats c;
    if (j.is_null()) return c;
    c.minimum = j.at("min").get<double>();
    c.percentile1 = j.at("p01").get<double>();
    c.penetrations = j.at("penetrations").get<uint64_t>();
    c.samples = j.at("samples").get<uint64_t>();
    return c;
}

nlohmann::json vec(const Vec3d& v) { return {v[0], v[1], v[2]}; }
Vec3d vecFromJson(const nlohmann::json& j) { return Vec3d(j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()); }

nlohmann::json toJson(const FrameRecord& r)
{
    const bool any = r.alive > 0;
    return {{"frame", r.frame},
            {"centroid", any ? vec(r.centroid) : nlohmann::json(nullptr)},
            {"boundsMin", any ? vec(r.bounds.min()) : nlohmann::json(nullptr)},
            {"boundsMax", any ? vec(r.bounds.max()) : nlohmann::json(nullptr)},
            {"alive", r.alive},
            {"removed", r.removed},
            {"substeps", r.substeps},
            {"maxSubsteps", r.maxSubsteps},
            {"dynamicSubsteps", r.dynamicSubsteps},
            {"clearance", {{"particles", toJson(r.particleClearance)}, {"dynamicVertices", toJson(r.dynamicClearance)}}}};
}

FrameRecord recordFromJson(const nlohmann::json& j)
{
    FrameRecord r;
    r.frame = j.at("frame").get<int>();
    r.alive = j.at("alive").get<uint64_t>();
    r.removed = j.at("removed").get<uint64_t>();
    r.substeps = j.at("substeps").get<uint64_t>();
    r.maxSubsteps = j.at("maxSubsteps").get<uint32_t>();
    r.dynamicSubsteps = j.at("dynamicSubsteps").get<uint32_t>();
    if (!j.at("centroid").is_null()) {
        r.centroid = vecFromJson(j.at("centroid"));
        r.bounds = BBoxd(vecFromJson(j.at("boundsMin")), vecFromJson(j.at("boundsMax")));
    }
    r.particleClearance = clearanceFromJson(j.at("clearance").at("particles"));
    r.dynamicClearance = clearanceFromJson(j.at("clearance").at("dynamicVertices"));
    return r;
}

nlohmann::json trackEntry(int frame, const DynamicState& s)
{
    const Quatd& q = s.pose.rotation;
    return {{"frame", frame},
            {"position", {s.pose.translation[0], s.pose.translation[1], s.pose.translation[2]}},
            {"orientation", {q.x(), q.y(), q.z(), q.w()}},
            {"velocity", {s.velocity[0], s.velocity[1], s.velocity[2]}}};
}

void accumulate(ClearanceStats& worst, const ClearanceStats& frame)
{
    if (frame.samples == 0) return;
    if (worst.samples == 0 || frame.minimum < worst.minimum) worst.minimum = frame.minimum;
    if (worst.samples == 0 || frame.percentile1 < worst.percentile1) worst.percentile1 = frame.percentile1;
    worst.penetrations += frame.penetrations;
    worst.samples += frame.samples;
}

/// The state file: what a resumed run needs, tagged with the scene it belongs to.
struct SavedRun {
    uint64_t sceneHash = 0;
    std::string simulatorState;
    nlohmann::json records = nlohmann::json::array(); ///< FrameRecords so far
    nlohmann::json tracks = nlohmann::json::object(); ///< per dynamic object, entries so far
};

std::string encode(const SavedRun& run)
{
    const std::string records = run.records.dump(), tracks = run.tracks.dump();
    std::string out = "vfield-run 1\n";
    const auto putBlock = [&out](const std::string& block) {
        out += std::to_string(block.size()) + "\n";
        out += block;
    };
    putBlock(std::to_string(run.sceneHash));
    putBlock(run.simulatorState);
    putBlock(records);
    putBlock(tracks);
    return out;
}

SavedRun decode(const std::string& bytes, const std::string& path)
{
    std::istringstream in(bytes);
    std::string header;
    std::getline(in, header);
    if (header != "vfield-run 1") throw FileError(path, "not a vfield run state");
    const auto getBlock = [&]() {
        std::string size;
        std::getline(in, size);
        std::size_t n = 0;
        try {
            n = std::stoull(size);
        } catch (const std::exception&) {
            throw FileError(path, "the run state is corrupt");
        }
        std::string block(n, '\0');
        in.read(block.data(), std::streamsize(n));
        if (std::size_t(in.gcount()) != n) throw FileError(path, "the run state is truncated");
        return block;
    };
    SavedRun run;
    run.sceneHash = std::stoull(getBlock());
    run.simulatorState = getBlock();
    try {
        run.records = nlohmann::json::parse(getBlock());
        run.tracks = nlohmann::json::parse(getBlock());
    } catch (const nlohmann::json::exception&) {
        throw FileError(path, "the run state is corrupt");
    }
    return run;
}

std::string readFile(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

} // namespace

SimulateSummary simulateScene(const Scene& scene, const std::string& outputDir, const SimulateOptions& options)
{
    const SimulationSetup& setup = scene.simulation;
    const int writeFirst = options.firstFrame.value_or(setup.firstFrame);
    const int writeLast = options.lastFrame.value_or(setup.lastFrame);
    if (writeFirst < setup.firstFrame || writeLast > setup.lastFrame || writeLast < writeFirst)
        throw ValueError("frames " + std::to_string(writeFirst) + "-" + std::to_string(writeLast) +
                         " are not within the scene's " + std::to_string(setup.firstFrame) + "-" +
                         std::to_string(setup.lastFrame));

    std::error_code ec;
    fs::create_directories(outputDir, ec);
    if (ec) throw FileError(outputDir, "cannot create the output folder: " + ec.message());
    const auto out = [&outputDir](const std::string& name) { return (fs::path(outputDir) / name).string(); };

    Simulator simulator(setup);
    const ClearanceProbe clearance(simulator);
    SimulateSummary summary;
    summary.warnings = clearance.warnings();
    if (!fs::exists(out("field.vdb"))) writeVdb(out("field.vdb"), {simulator.staticForceGrid()});

    // Resume after the last complete frame of an earlier run of this scene.
    SavedRun run;
    run.sceneHash = scene.simulationHash;
    const std::string statePath = out("state.bin");
    if (fs::exists(statePath)) {
        SavedRun saved = decode(readFile(statePath), statePath);
        if (saved.sceneHash == scene.simulationHash) {
            simulator.restoreState(saved.simulatorState);
            if (simulator.frame() > writeLast)
                throw ValueError("the output folder already holds frames up to " + std::to_string(simulator.frame()));
            run = std::move(saved);
            summary.resumedAfterFrame = simulator.frame();
        } else {
            throw FileError(outputDir, "holds a simulation of another scene (or of one whose simulated parts were edited): "
                                       "use another folder or remove it");
        }
    }

    std::vector<std::size_t> dynamic;
    for (std::size_t i = 0; i < simulator.objects().size(); ++i)
        if (simulator.objects()[i].spec->isDynamic) dynamic.push_back(i);

    const auto start = std::chrono::steady_clock::now();
    const bool resumed = summary.resumedAfterFrame >= 0;
    const int total = writeLast - (resumed ? simulator.frame() : setup.firstFrame - 1);
    int done = 0;
    // A fresh run first records the initial state (the first frame) without
    // stepping; a resumed run continues after its last complete frame.
    for (bool first = !resumed; simulator.frame() < writeLast || first; first = false) {
        if (!first) simulator.advanceFrame();
        const int frame = simulator.frame();

        FrameRecord record;
        record.frame = frame;
        record.alive = simulator.particles().size();
        record.removed = simulator.removedTotal();
        record.substeps = simulator.lastStep().substeps;
        record.maxSubsteps = simulator.lastStep().maxSubsteps;
        record.dynamicSubsteps = simulator.lastStep().dynamicSubsteps;
        record.particleClearance = clearance.measureParticles(simulator.particles());
        for (const Vec3f& p : simulator.particles().position) {
            record.centroid += Vec3d(p);
            record.bounds.expand(Vec3d(p));
        }
        if (record.alive > 0) record.centroid /= double(record.alive);
        std::vector<Vec3d> vertices;
        for (const std::size_t i : dynamic) {
            const std::vector<Vec3d> v = ClearanceProbe::vertices(simulator.objects()[i], simulator.objectStates()[i].pose);
            vertices.insert(vertices.end(), v.begin(), v.end());
            run.tracks[simulator.objects()[i].spec->name].push_back(trackEntry(frame, simulator.objectStates()[i]));
        }
        record.dynamicClearance = clearance.measure(vertices);
        run.records.push_back(toJson(record));

        if (frame >= writeFirst) {
            const DensityGrids volume = splatParticles(simulator.particles(), scene.volume);
            writeVdb(out(frameFileName("density", frame, "vdb")), {volume.density, volume.velocity});
            writeVdb(out(frameFileName("particles", frame, "vdb")), {makeParticleGrid(simulator.particles())});
        }
        nlohmann::json stats = {{"fps", setup.fps}, {"frames", run.records}};
        writeTextAtomically(out("stats.json"), stats.dump(1) + "\n");
        nlohmann::json tracks = {{"fps", setup.fps},
                                 {"convention", "position: the object's pivot (its mesh's origin) in world space; "
                                                "orientation: unit quaternion [x, y, z, w] rotating object space "
                                                "(nose +x, up +y) into world space; velocity: world units per second"},
                                 {"objects", run.tracks}};
        writeTextAtomically(out("tracks.json"), tracks.dump(1) + "\n");
        run.simulatorState = simulator.serializeState();
        writeTextAtomically(statePath, encode(run)); // last: marks the frame complete

        ++done;
        if (options.progress) {
            FrameProgress progress;
            progress.frame = frame;
            progress.done = done;
            progress.total = total;
            progress.alive = record.alive;
            progress.elapsedSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            options.progress(progress);
        }
    }

    for (const nlohmann::json& r : run.records) {
        summary.frames.push_back(recordFromJson(r));
        accumulate(summary.worstParticles, summary.frames.back().particleClearance);
        accumulate(summary.worstDynamic, summary.frames.back().dynamicClearance);
    }
    return summary;
}

} // namespace vfield
