#include <vfield/run/simulation_run.h>

#include <vfield/run/frame_volume.h>

#include <vfield/core/error.h>
#include <vfield/core/stopwatch.h>
#include <vfield/core/vdb_file.h>
#include <vfield/host/host_scene.h>
#include <vfield/scene/inputs_hash.h>
#include <vfield/scene/memory_estimate.h>
#include <vfield/volume/particle_grid.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>

namespace fs = std::filesystem;

namespace vfield {

namespace {

/// state.bin holds every particle: hundreds of megabytes for millions, more
/// than a frame's simulation takes to write. It is saved when the time since
/// the last save is this many times what that save took (and after the last
/// frame), so saving costs at most a twentieth, and a small simulation's
/// state is saved after every frame. A run resumed from it steps again
/// through the frames written after it, keeping them.
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

/// Refuses, before anything is built or written, a scene estimated to need
/// more memory than the options allow or than is available (a part of a
/// sharded simulation holds its share of the particles).
void refuseIfTooLarge(const Scene& scene, const SimulateOptions& options)
{
    const std::optional<double> limit = options.maxMemoryBytes ? options.maxMemoryBytes : availableMemory();
    if (!limit) return;
    Scene share = scene;
    if (options.part)
        for (CloudSettings& cloud : share.simulation.clouds)
            cloud.count = options.part->isObjects() ? 0 : (cloud.count + options.part->count - 1) / options.part->count;
    try {
        requireMemoryWithin(estimateSimulationMemory(share), *limit,
                            options.maxMemoryBytes ? "the limit" : "the memory available");
    } catch (const OptionError& e) {
        throw FileError(scene.path, e.what());
    }
}

/// What a run simulates, and into which folder: the whole simulation into
/// the output folder, or one part of a sharded one (shard_part.h) into its
/// folder within it, with an inputs hash of its own.
struct RunPart {
    std::optional<ShardPart> part;
    bool isShard = false; ///< a shard of the particles, not the objects' part
    std::string dir;
    uint64_t inputsHash = 0;
    /// A shard replays the dynamic objects from the objects' part's tracks.
    Simulator::ObjectReplay replay;

    RunPart(const Scene& scene, const std::string& outputDir, const std::optional<ShardPart>& shardPart, int writeLast)
        : part(shardPart), isShard(part && !part->isObjects()), dir(part ? part->folder(outputDir) : outputDir)
    {
        const SimulationSettings& simulation = scene.simulation;
        const uint64_t simulationHash = simulationInputsHash(simulation, scene.volume);
        inputsHash = part ? part->inputsHash(simulationHash) : simulationHash;
        const bool hasDynamic = std::any_of(simulation.objects.begin(), simulation.objects.end(),
                                            [](const ObjectSettings& o) { return o.isDynamic; });
        if (isShard && hasDynamic) replay = objectsReplay(outputDir, simulationHash, writeLast);
    }

    /// Whether its frames' files are written: the whole simulation's and a
    /// shard's (its particles alone), not the objects' part's.
    bool writesFrames() const { return !part || isShard; }
};

/// One run of simulateScene, its steps in the order they are taken.
class SimulationRun {
public:
    SimulationRun(const Scene& scene, const RunPart& part, std::pair<int, int> frames, const SimulateOptions& options)
        : mScene(scene), mSetup(scene.simulation), mOptions(options), mPart(part), mWriteFirst(frames.first),
          mWriteLast(frames.second), mFolder(part.dir), mSimulator(mSetup, [this](const std::string& step) { preparing(step); }),
          mClearance(mSimulator)
    {
        if (part.part) {
            const ShardPart shard = *part.part;
            mSimulator.keepParticles([shard](uint32_t id) { return shard.holds(id); });
        }
        if (part.replay) mSimulator.replayObjects(part.replay);
        mSummary.warnings = mSimulator.meshReports();
        for (const std::string& warning : mClearance.warnings()) mSummary.warnings.push_back(warning);
        mRun.scenePath = fs::weakly_canonical(scene.path).string();
        mRun.inputsHash = part.inputsHash;
    }

    /// Resumes after the last complete frame of an earlier run of this scene
    /// with the same inputs, or, from a frame of it that is no longer as
    /// written, simulates again; a run of an earlier edit of the scene is
    /// stale and cleared.
    void resumeOrRecover()
    {
        if (!mFolder.hasRunState()) return;
        RunState saved = mFolder.readRunState();
        if (saved.scenePath != mRun.scenePath)
            throw FileError(mPart.dir,
                            "holds a simulation of another scene (" + saved.scenePath + "): use another folder or remove it");
        if (saved.simulatorState.empty())
            throw FileError(mPart.dir,
                            "holds the merge of a sharded simulation (shards/): simulate into another folder or remove it");
        if (saved.inputsHash != mRun.inputsHash) {
            mFolder.clear();
            mSummary.restartedStale = true;
            return;
        }
        mRun = std::move(saved);
        preparing("checking the " + std::to_string(mRun.records.size()) + " frames an earlier run wrote");
        const std::optional<BadFrame> bad = firstBadFrame(mFolder, mRun, mWriteFirst, mPart.writesFrames());
        if (bad) recoverBefore(*bad);
        else resume();
    }

    /// The static objects' field, for looking at; the merge of a sharded
    /// simulation takes the objects' part's.
    void writeStaticField()
    {
        if (mPart.isShard || fs::exists(mFolder.fieldFile())) return;
        preparing("writing the static field, " + mFolder.fieldFile());
        const openvdb::Vec3SGrid::Ptr field = mSimulator.staticForceGrid();
        field->setSaveFloatAsHalf(true); // the dense continuous field: up to 200 MB in full floats
        writeVdb(mFolder.fieldFile(), {field});
    }

    /// Every frame to the last to write: a fresh run first records the
    /// initial state (the first frame) without stepping; a resumed run goes
    /// on after its last complete frame. Each frame is recorded, its files
    /// written, stats.json and tracks.json rewritten, and the run's state
    /// saved now and then (saveCheckpointIfDue).
    void simulateFrames()
    {
        const std::vector<FieldRecord> fields = fieldRecords();
        std::vector<std::size_t> dynamic;
        for (std::size_t i = 0; i < mSimulator.objects().size(); ++i)
            if (mSimulator.objects()[i].spec->isDynamic) dynamic.push_back(i);

        const Stopwatch runWatch;
        const bool resumed = mSummary.resumedAfterFrame >= 0;
        const int total = mWriteLast - (resumed ? mSimulator.frame() : mSetup.firstFrame - 1);
        int done = 0;
        for (bool first = !resumed; mSimulator.frame() < mWriteLast || first; first = false) {
            mClosestInFrame.clear();
            mPairSeconds = 0.0;
            Stopwatch frameWatch, stageWatch;
            // A shard replays the objects: their part measured them. Every
            // later frame's last substep ends at its poses.
            if (first && !mPart.isShard) measurePairs();
            else if (!first) mSimulator.advanceFrame([this] { measurePairs(); });
            const int frame = mSimulator.frame();
            for (const std::size_t i : dynamic)
                mRun.tracks.add(mSimulator.objects()[i].spec->name, frame, mSimulator.objectStates()[i]);
            const auto kept = mKeptFrames.find(frame);
            const FrameRecord record =
                kept != mKeptFrames.end() ? kept->second : recordFrame(stageWatch.lap() - mPairSeconds, frameWatch);
            if (kept == mKeptFrames.end()) mSummary.stages += record.stages;
            mRun.records.push_back(record);
            mFolder.writeStats({mRun.inputsHash, mSetup.fps, fields, mRun.records});
            mFolder.writeTracks(mRun.tracks, mSetup.fps);
            saveCheckpointIfDue(frame);
            reportProgress(frame, ++done, total, record.alive, runWatch.seconds());
        }
    }

    SimulateSummary finish()
    {
        if (mOptions.finished) mOptions.finished(mWriteLast);
        if (!mPart.part) writeHostScene(mScene, mFolder); // the merge writes a sharded simulation's
        mSummary.addFrames(mRun.records);
        return std::move(mSummary);
    }

private:
    void preparing(const std::string& step) const
    {
        if (mOptions.preparing) mOptions.preparing(step);
    }

    /// After the saved state, and the frames written after it that are still
    /// as written (kept, stepped through again for the state).
    void resume()
    {
        mSimulator.restoreState(mRun.simulatorState);
        std::string().swap(mRun.simulatorState); // from here on streamed from the simulator
        if (mSimulator.frame() > mWriteLast)
            throw ValueError("the output folder already holds frames up to " + std::to_string(mSimulator.frame()));
        mSummary.resumedAfterFrame = mSimulator.frame();
        mKeptFrames = framesWrittenAfter(mFolder, mRun.inputsHash, mSimulator.frame());
        if (!mKeptFrames.empty() && mKeptFrames.rbegin()->first > mWriteLast)
            throw ValueError("the output folder already holds frames up to " + std::to_string(mKeptFrames.rbegin()->first));
        while (mKeptFrames.count(mSummary.resumedAfterFrame + 1)) ++mSummary.resumedAfterFrame;
    }

    /// Back to the last good frame before a bad one: from the initial state,
    /// as every run starts, stepping without writing (bit for bit what was
    /// simulated before).
    void recoverBefore(const BadFrame& bad)
    {
        const int good = bad.frame - 1;
        mSummary.resimulatedFrom = bad.frame;
        mSummary.resimulatedBecause = std::string(enumName(bad.check.status)) + ": " + bad.check.detail;
        mRun.records.erase(
            std::remove_if(mRun.records.begin(), mRun.records.end(), [good](const FrameRecord& r) { return r.frame > good; }),
            mRun.records.end());
        mRun.tracks.keepUpTo(good);
        preparing("simulating again up to frame " + std::to_string(good) + ", as written before");
        while (mSimulator.frame() < good) mSimulator.advanceFrame();
        if (good >= mSetup.firstFrame) mSummary.resumedAfterFrame = good;
    }

    std::vector<FieldRecord> fieldRecords() const
    {
        std::vector<FieldRecord> fields;
        for (const SimObject& object : mSimulator.objects()) {
            if (!object.field) continue;
            fields.push_back({object.spec->name, enumName(object.field->method()), object.fieldSeconds,
                              uint64_t(object.field->memoryBytes()),
                              object.field->finestCellSize() * object.spec->transform.scale});
        }
        return fields;
    }

    /// Objects are measured against each other at the end of every substep
    /// of theirs, not only at frames: two aircraft can pass through each
    /// other between frames. A frame records each pair's closest approach.
    void measurePairs()
    {
        const Stopwatch watch;
        for (const PairClearance& pair : mClearance.measureObjects()) keepClosest(mClosestInFrame, pair);
        mPairSeconds += watch.seconds();
    }

    /// The record of the frame the simulator has just reached, its particles
    /// measured and its files written (from the first frame to write on).
    FrameRecord recordFrame(double advectionSeconds, const Stopwatch& frameWatch)
    {
        Stopwatch stageWatch;
        const StepStats& step = mSimulator.lastStep();
        FrameRecord record;
        record.stages.advection = advectionSeconds;
        record.frame = mSimulator.frame();
        record.alive = mSimulator.particles().size();
        record.removed = mSimulator.removedTotal();
        record.substeps = step.substeps;
        record.maxSubsteps = step.maxSubsteps;
        record.dynamicSubsteps = step.dynamicSubsteps;
        record.contacts = step.contacts;
        record.endedInside = step.endedInside;
        record.maxRollChange = step.maxRollChange;
        record.particleClearance = mClearance.measureParticles();
        record.stages.clearance = stageWatch.lap() + mPairSeconds;
        record.objectPairs = mClosestInFrame;
        for (const Vec3f& p : mSimulator.particles().position) {
            record.centroid += Vec3d(p);
            record.bounds.expand(Vec3d(p));
        }
        if (record.alive > 0) record.centroid /= double(record.alive);
        const bool writes = record.frame >= mWriteFirst;
        if (writes && mPart.isShard) {
            record.files = FrameFiles{
                {},
                mFolder.writeParticles(record.frame, makeParticleGrid(mSimulator.particles(), ParticlePrecision::Full, true),
                                       mRun.inputsHash)};
            record.stages.write = stageWatch.lap();
        } else if (writes && !mPart.part) {
            record.files =
                writeFrameVolume(mFolder, record.frame, mSimulator.particles(), mScene.volume, mRun.inputsHash, record.stages);
        }
        record.seconds = frameWatch.seconds();
        return record;
    }

    /// Saves the run's state, which marks the frames before it complete,
    /// after the last frame and whenever the time since the last save is
    /// kCheckpointCost times what that save took.
    void saveCheckpointIfDue(int frame)
    {
        if (frame != mWriteLast && mSinceCheckpoint.seconds() < kCheckpointCost * mCheckpointSeconds) return;
        const Stopwatch save;
        mFolder.writeRunState(mRun, [this](std::ostream& out) { mSimulator.writeState(out); });
        mCheckpointSeconds = save.seconds();
        mSinceCheckpoint.lap();
    }

    void reportProgress(int frame, int done, int total, uint64_t alive, double elapsedSeconds) const
    {
        if (!mOptions.progress) return;
        FrameProgress progress;
        progress.frame = frame;
        progress.done = done;
        progress.total = total;
        progress.alive = alive;
        progress.elapsedSeconds = elapsedSeconds;
        mOptions.progress(progress);
    }

    const Scene& mScene;
    const SimulationSettings& mSetup;
    const SimulateOptions& mOptions;
    const RunPart& mPart;
    const int mWriteFirst, mWriteLast;
    const SimFolder mFolder;
    Simulator mSimulator;
    const ClearanceProbe mClearance;
    SimulateSummary mSummary;
    RunState mRun;
    std::map<int, FrameRecord> mKeptFrames; ///< written after the saved state (framesWrittenAfter)
    std::vector<PairClearance> mClosestInFrame;
    double mPairSeconds = 0.0;
    Stopwatch mSinceCheckpoint;
    double mCheckpointSeconds = 0.0;
};

} // namespace

std::pair<int, int> framesToWrite(const SimulationSettings& setup, const SimulateOptions& options)
{
    const int first = options.firstFrame.value_or(setup.firstFrame), last = options.lastFrame.value_or(setup.lastFrame);
    if (first < setup.firstFrame || last > setup.lastFrame || last < first)
        throw ValueError("frames " + std::to_string(first) + "-" + std::to_string(last) + " are not within the scene's " +
                         std::to_string(setup.firstFrame) + "-" + std::to_string(setup.lastFrame));
    return {first, last};
}

SimulateSummary simulateScene(const Scene& scene, const std::string& outputDir, const SimulateOptions& options)
{
    const std::pair<int, int> frames = framesToWrite(scene.simulation, options);
    refuseIfTooLarge(scene, options);
    const RunPart part(scene, outputDir, options.part, frames.second);
    const FolderLock lock(part.dir, "vfield simulate", options.waitForFolder);
    SimulationRun run(scene, part, frames, options);
    run.resumeOrRecover();
    run.writeStaticField();
    run.simulateFrames();
    return run.finish();
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
