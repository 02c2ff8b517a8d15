#include <vfield/scene/simulation_run.h>

#include <vfield/core/error.h>
#include <vfield/core/stopwatch.h>
#include <vfield/core/vdb_file.h>
#include <vfield/scene/host_scene.h>
#include <vfield/scene/inputs_hash.h>
#include <vfield/scene/memory_estimate.h>
#include <vfield/volume/density_splat.h>
#include <vfield/volume/particle_grid.h>

#include <tbb/parallel_for.h>

#include <filesystem>
#include <map>
#include <optional>

namespace fs = std::filesystem;

namespace vfield {

namespace {

/// state.bin holds every particle: hundreds of megabytes for millions, more
/// than a frame's simulation takes to write. It is saved when the time since
/// the last save is this many times what that save took (and after the last
/// frame), so saving costs at most a twentieth; a main job's 12 MB is saved
/// after every frame. A run resumed from it steps again through the frames
/// written after it, keeping them.
constexpr double kCheckpointCost = 20.0;

/// Keeps the smaller of the pair's distance and the one already held for it.
void keepClosest(std::vector<PairClearance>& closest, const PairClearance& pair)
{
    const auto same = std::find_if(closest.begin(), closest.end(),
                                   [&](const PairClearance& c) { return c.first == pair.first && c.second == pair.second; });
    if (same == closest.end()) closest.push_back(pair);
    else if (pair.minimum < same->minimum) *same = pair;
}

struct BadFrame {
    int frame;
    FrameCheck check;
};

/// The first frame from writeFirst on that the saved run wrote and that is no
/// longer as written (missing, foreign or corrupt); none for a run that
/// writes no frames (a sharded simulation's objects' part). Frames are checked in
/// parallel: it reads their bytes.
std::optional<BadFrame> firstBadFrame(const SimFolder& folder, const RunState& run, int writeFirst, bool writesFrames)
{
    std::vector<FrameCheck> checks(run.records.size());
    tbb::parallel_for(std::size_t(0), run.records.size(), [&](std::size_t i) {
        if (writesFrames && run.records[i].frame >= writeFirst) checks[i] = folder.checkFrame(run.records[i], run.inputsHash);
    });
    for (std::size_t i = 0; i < checks.size(); ++i)
        if (checks[i].status != FrameCheck::Status::Good) return BadFrame{run.records[i].frame, checks[i]};
    return std::nullopt;
}

/// The frames an earlier run wrote after the state it left (after frame
/// `after`: it saves its state only now and then, see kCheckpointCost) that
/// stats.json records and that are still as written, by frame. A resumed run
/// steps through them again for the state, and keeps them.
std::map<int, FrameRecord> framesWrittenAfter(const SimFolder& folder, uint64_t inputsHash, int after)
{
    std::map<int, FrameRecord> kept;
    if (!fs::exists(folder.statsFile())) return kept;
    StatsFile stats;
    try {
        stats = folder.readStats();
    } catch (const FileError&) {
        return kept; // unreadable: those frames are simulated and written again
    }
    if (stats.inputsHash != inputsHash) return kept;
    std::vector<FrameRecord> later;
    for (FrameRecord& r : stats.frames)
        if (r.frame > after && r.files) later.push_back(std::move(r));
    std::vector<uint8_t> good(later.size());
    tbb::parallel_for(std::size_t(0), later.size(), [&](std::size_t i) {
        good[i] = folder.checkFrame(later[i], inputsHash).status == FrameCheck::Status::Good;
    });
    for (std::size_t i = 0; i < later.size(); ++i)
        if (good[i]) kept[later[i].frame] = std::move(later[i]);
    return kept;
}

/// A shard's replay of the dynamic objects: the tracks of the objects' part,
/// which must have been simulated through lastFrame from the same inputs.
Simulator::ObjectReplay objectsReplay(const std::string& outputDir, uint64_t inputsHash, int lastFrame)
{
    const ShardPart objects = ShardPart::objects();
    const SimFolder folder(objects.folder(outputDir));
    const std::string rerun = "run its objects' part first (vfield simulate SCENE -o " + outputDir + " --shard objects)";
    if (!folder.hasRunState()) throw FileError(folder.path(), "no objects' part here: " + rerun);
    RunState saved = folder.readRunState();
    if (saved.inputsHash != objects.inputsHash(inputsHash))
        throw FileError(folder.path(), "holds the objects of another simulation or of an earlier edit of the scene: " + rerun);
    if (saved.records.empty() || saved.records.back().frame < lastFrame)
        throw FileError(folder.path(), "holds the objects up to frame " +
                                           std::to_string(saved.records.empty() ? 0 : saved.records.back().frame) + ", not " +
                                           std::to_string(lastFrame) + ": " + rerun);
    auto tracks = std::make_shared<const Tracks>(std::move(saved.tracks));
    return [tracks](const SimObject& object, int frame) {
        const TrackEntry& entry = tracks->at(object.spec->name, frame);
        DynamicState state;
        state.pose = entry.pose;
        state.velocity = entry.velocity;
        return state;
    };
}

} // namespace

std::pair<int, int> framesToWrite(const SimulationSetup& setup, const SimulateOptions& options)
{
    const int first = options.firstFrame.value_or(setup.firstFrame), last = options.lastFrame.value_or(setup.lastFrame);
    if (first < setup.firstFrame || last > setup.lastFrame || last < first)
        throw ValueError("frames " + std::to_string(first) + "-" + std::to_string(last) + " are not within the scene's " +
                         std::to_string(setup.firstFrame) + "-" + std::to_string(setup.lastFrame));
    return {first, last};
}

SimulateSummary simulateScene(const Scene& scene, const std::string& outputDir, const SimulateOptions& options)
{
    const SimulationSetup& setup = scene.simulation;
    const std::pair<int, int> frames = framesToWrite(setup, options);
    const int writeFirst = frames.first, writeLast = frames.second;

    // Before anything is written or built: a scene too large is refused at
    // once (a part of a sharded simulation holds its share of the particles).
    const std::optional<double> limit = options.maxMemoryBytes ? options.maxMemoryBytes : availableMemory();
    if (limit) {
        Scene share = scene;
        if (options.part)
            for (CloudSpec& cloud : share.simulation.clouds)
                cloud.count = options.part->isObjects() ? 0 : (cloud.count + options.part->count - 1) / options.part->count;
        try {
            requireMemoryWithin(estimateSimulationMemory(share), *limit,
                                options.maxMemoryBytes ? "the limit" : "the memory available");
        } catch (const OptionError& e) {
            throw FileError(scene.path, e.what());
        }
    }

    // A part of a sharded simulation has a folder of its own within it.
    const std::optional<ShardPart>& part = options.part;
    const bool isShard = part && !part->isObjects();
    const std::string dir = part ? part->folder(outputDir) : outputDir;
    const uint64_t inputsHash = simulationInputsHash(setup, scene.volume);
    const Simulator::ObjectReplay replay =
        isShard && std::any_of(setup.objects.begin(), setup.objects.end(), [](const ObjectSpec& o) { return o.isDynamic; })
            ? objectsReplay(outputDir, inputsHash, writeLast)
            : Simulator::ObjectReplay();

    const FolderLock lock(dir, "vfield simulate", options.waitForFolder);
    const SimFolder folder(dir);

    const auto preparing = [&](const std::string& step) {
        if (options.preparing) options.preparing(step);
    };
    Simulator simulator(setup, preparing);
    if (part) simulator.keepParticles([&](uint32_t id) { return part->holds(id); });
    if (replay) simulator.replayObjects(replay);
    const ClearanceProbe clearance(simulator);
    SimulateSummary summary;
    summary.warnings = simulator.meshReports();
    for (const std::string& warning : clearance.warnings()) summary.warnings.push_back(warning);

    // Resume after the last complete frame of an earlier run of this scene with
    // the same inputs; a run of an earlier edit of it is stale.
    RunState run;
    run.scenePath = fs::weakly_canonical(scene.path).string();
    run.inputsHash = part ? part->inputsHash(inputsHash) : inputsHash;
    std::map<int, FrameRecord> keptFrames; // written after the saved state (framesWrittenAfter)
    if (folder.hasRunState()) {
        RunState saved = folder.readRunState();
        if (saved.scenePath != run.scenePath)
            throw FileError(dir,
                            "holds a simulation of another scene (" + saved.scenePath + "): use another folder or remove it");
        if (saved.simulatorState.empty())
            throw FileError(dir, "holds the merge of a sharded simulation (shards/): simulate into another folder or remove it");
        if (saved.inputsHash == run.inputsHash) {
            run = std::move(saved);
            preparing("checking the " + std::to_string(run.records.size()) + " frames an earlier run wrote");
            const std::optional<BadFrame> bad = firstBadFrame(folder, run, writeFirst, !part || isShard);
            if (!bad) {
                simulator.restoreState(run.simulatorState);
                std::string().swap(run.simulatorState); // from here on streamed from the simulator
                if (simulator.frame() > writeLast)
                    throw ValueError("the output folder already holds frames up to " + std::to_string(simulator.frame()));
                summary.resumedAfterFrame = simulator.frame();
                keptFrames = framesWrittenAfter(folder, run.inputsHash, simulator.frame());
                if (!keptFrames.empty() && keptFrames.rbegin()->first > writeLast)
                    throw ValueError("the output folder already holds frames up to " +
                                     std::to_string(keptFrames.rbegin()->first));
                while (keptFrames.count(summary.resumedAfterFrame + 1)) ++summary.resumedAfterFrame;
            } else {
                // Back to the last good frame: from the initial state, as
                // every run starts, stepping without writing (bit for bit what
                // was simulated before).
                const int good = bad->frame - 1;
                summary.resimulatedFrom = bad->frame;
                summary.resimulatedBecause = std::string(enumName(bad->check.status)) + ": " + bad->check.detail;
                run.records.erase(std::remove_if(run.records.begin(), run.records.end(),
                                                 [good](const FrameRecord& r) { return r.frame > good; }),
                                  run.records.end());
                run.tracks.keepUpTo(good);
                preparing("simulating again up to frame " + std::to_string(good) + ", as written before");
                while (simulator.frame() < good) simulator.advanceFrame();
                if (good >= setup.firstFrame) summary.resumedAfterFrame = good;
            }
        } else {
            folder.clear();
            summary.restartedStale = true;
        }
    }
    if (!isShard && !fs::exists(folder.fieldFile())) { // the merge takes the objects' part's
        preparing("writing the static field, " + folder.fieldFile());
        const openvdb::Vec3SGrid::Ptr field = simulator.staticForceGrid();
        field->setSaveFloatAsHalf(true); // for looking at; the dense continuous field is 112 MB in full floats
        writeVdb(folder.fieldFile(), {field});
    }

    std::vector<std::size_t> dynamic;
    std::vector<FieldRecord> fields;
    for (std::size_t i = 0; i < simulator.objects().size(); ++i) {
        const SimObject& object = simulator.objects()[i];
        if (object.spec->isDynamic) dynamic.push_back(i);
        if (!object.field) continue;
        fields.push_back({object.spec->name, enumName(object.field->method()), object.fieldSeconds,
                          uint64_t(object.field->memoryBytes()), object.field->finestCellSize() * object.spec->transform.scale});
    }

    const Stopwatch runWatch;
    const bool resumed = summary.resumedAfterFrame >= 0;
    const int total = writeLast - (resumed ? simulator.frame() : setup.firstFrame - 1);
    int done = 0;
    // A fresh run first records the initial state (the first frame) without
    // stepping; a resumed run continues after its last complete frame.
    // Objects are measured against each other at the end of every substep of
    // theirs, not only at frames: two aircraft can pass through each other
    // between frames. A frame records each pair's closest approach.
    std::vector<PairClearance> closestInFrame;
    double pairSeconds = 0.0;
    const auto measurePairs = [&] {
        const Stopwatch watch;
        for (const PairClearance& pair : clearance.measureObjects()) keepClosest(closestInFrame, pair);
        pairSeconds += watch.seconds();
    };
    // The record of the frame the simulator has just reached, its particles
    // measured and its files written (from writeFirst on).
    const auto simulateFrame = [&](double advectionSeconds, const Stopwatch& frameWatch) {
        Stopwatch stageWatch;
        FrameRecord record;
        record.stages.advection = advectionSeconds;
        record.frame = simulator.frame();
        record.alive = simulator.particles().size();
        record.removed = simulator.removedTotal();
        record.substeps = simulator.lastStep().substeps;
        record.maxSubsteps = simulator.lastStep().maxSubsteps;
        record.dynamicSubsteps = simulator.lastStep().dynamicSubsteps;
        record.contacts = simulator.lastStep().contacts;
        record.endedInside = simulator.lastStep().endedInside;
        record.maxRollChange = simulator.lastStep().maxRollChange;
        record.particleClearance = clearance.measureParticles();
        record.stages.clearance = stageWatch.lap() + pairSeconds;
        record.objectPairs = closestInFrame;
        for (const Vec3f& p : simulator.particles().position) {
            record.centroid += Vec3d(p);
            record.bounds.expand(Vec3d(p));
        }
        if (record.alive > 0) record.centroid /= double(record.alive);
        if (record.frame >= writeFirst && isShard) {
            record.files = folder.writeParticles(
                record.frame, makeParticleGrid(simulator.particles(), ParticlePrecision::Full, true), run.inputsHash);
            record.stages.write = stageWatch.lap();
        } else if (record.frame >= writeFirst && !part) {
            record.files = folder.writeFrame(record.frame, simulator.particles(), scene.volume, run.inputsHash, record.stages);
        }
        record.seconds = frameWatch.seconds();
        return record;
    };
    Stopwatch sinceCheckpoint;
    double checkpointSeconds = 0.0;
    for (bool first = !resumed; simulator.frame() < writeLast || first; first = false) {
        closestInFrame.clear();
        pairSeconds = 0.0;
        Stopwatch frameWatch, stageWatch;
        // A shard replays the objects: their part measured them.
        if (first && !isShard) measurePairs(); // the initial poses; every later frame's last substep ends at it
        else if (!first) simulator.advanceFrame(measurePairs);
        const int frame = simulator.frame();
        for (const std::size_t i : dynamic) run.tracks.add(simulator.objects()[i].spec->name, frame, simulator.objectStates()[i]);
        const auto kept = keptFrames.find(frame);
        const FrameRecord record =
            kept != keptFrames.end() ? kept->second : simulateFrame(stageWatch.lap() - pairSeconds, frameWatch);
        if (kept == keptFrames.end()) summary.stages += record.stages;
        run.records.push_back(record);
        folder.writeStats({run.inputsHash, setup.fps, fields, run.records});
        folder.writeTracks(run.tracks, setup.fps);
        // Last: marks the frames before it complete. Saved when the time since
        // the last save is kCheckpointCost times what that save took.
        if (frame == writeLast || sinceCheckpoint.seconds() >= kCheckpointCost * checkpointSeconds) {
            const Stopwatch save;
            folder.writeRunState(run, [&](std::ostream& out) { simulator.writeState(out); });
            checkpointSeconds = save.seconds();
            sinceCheckpoint.lap();
        }

        ++done;
        if (options.progress) {
            FrameProgress progress;
            progress.frame = frame;
            progress.done = done;
            progress.total = total;
            progress.alive = record.alive;
            progress.elapsedSeconds = runWatch.seconds();
            options.progress(progress);
        }
    }

    if (options.finished) options.finished(writeLast);
    if (!part) writeHostScene(scene, folder); // the merge writes a sharded simulation's
    summary.addFrames(run.records);
    return summary;
}

void SimulateSummary::addFrames(const std::vector<FrameRecord>& records)
{
    frames = records;
    for (const FrameRecord& r : frames) {
        worstParticles.add(r.particleClearance);
        contacts += r.contacts;
        endedInside += r.endedInside;
        for (const PairClearance& pair : r.objectPairs) {
            if (pair.minimum < 0.0) ++overlappingPairFrames;
            keepClosest(closestPairs, pair);
        }
    }
}

} // namespace vfield
