#include <vfield/run/shard_merge.h>

#include <vfield/run/frame_volume.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>
#include <vfield/core/stopwatch.h>
#include <vfield/host/host_scene.h>
#include <vfield/scene/inputs_hash.h>
#include <vfield/volume/particle_grid.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <filesystem>
#include <map>

namespace fs = std::filesystem;

namespace vfield {

namespace {

/// A part of the simulation as its run left it: its records by frame.
struct PartRecords {
    ShardPart part;
    SimFolder folder;
    uint64_t inputsHash = 0;
    std::vector<FieldRecord> fields;
    std::map<int, FrameRecord> frames;
};

/// The part's records, which must reach lastFrame and come from the same inputs.
PartRecords readPart(const ShardPart& part, const std::string& outputDir, uint64_t simulationHash, int lastFrame)
{
    PartRecords records{part, SimFolder(part.folder(outputDir)), part.inputsHash(simulationHash), {}, {}};
    const std::string rerun = " (vfield simulate SCENE -o " + outputDir + " --shard " + part.text() + ")";
    if (!fs::exists(records.folder.statsFile())) throw FileError(records.folder.path(), "not simulated yet" + rerun);
    StatsFile stats = records.folder.readStats();
    if (stats.inputsHash != records.inputsHash)
        throw FileError(records.folder.path(), "made from another scene or an earlier edit of it: simulate it again" + rerun);
    records.fields = stats.fields;
    for (FrameRecord& r : stats.frames) records.frames[r.frame] = std::move(r);
    const int reached = records.frames.empty() ? 0 : records.frames.rbegin()->first;
    if (reached < lastFrame)
        throw FileError(records.folder.path(), "simulated up to frame " + std::to_string(reached) + ", not " +
                                                   std::to_string(lastFrame) + ": finish it" + rerun);
    return records;
}

const FrameRecord& recordOf(const PartRecords& part, int frame)
{
    const auto found = part.frames.find(frame);
    if (found == part.frames.end()) throw FileError(part.folder.statsFile(), "has no record of frame " + std::to_string(frame));
    return found->second;
}

/// The frame's record of the whole simulation: the objects' measures and the
/// shards' particles summed; seconds and stages are every part's.
FrameRecord combinedRecord(const FrameRecord& objects, const std::vector<const FrameRecord*>& shards)
{
    FrameRecord record = objects;
    record.files.reset();
    Vec3d centroidSum(0.0);
    for (const FrameRecord* shard : shards) {
        record.alive += shard->alive;
        record.removed += shard->removed;
        record.substeps += shard->substeps;
        record.contacts += shard->contacts;
        record.endedInside += shard->endedInside;
        record.maxSubsteps = std::max(record.maxSubsteps, shard->maxSubsteps);
        record.seconds += shard->seconds;
        record.stages += shard->stages;
        record.particleClearance.add(shard->particleClearance);
        if (shard->alive == 0) continue;
        centroidSum += shard->centroid * double(shard->alive);
        record.bounds.expand(shard->bounds);
    }
    if (record.alive > 0) record.centroid = centroidSum / double(record.alive);
    return record;
}

/// The shards' particles at frame, together: in id order, then in spatial
/// order (ties by id) over their box, as the splat reads fastest. The same
/// set in the same order for any shard files holding it.
ParticleSet gatherParticles(const std::vector<PartRecords>& shards, int frame)
{
    std::vector<ParticleSet> parts(shards.size());
    tbb::parallel_for(std::size_t(0), shards.size(), [&](std::size_t s) {
        const PartRecords& shard = shards[s];
        const FrameCheck check = shard.folder.checkFrame(recordOf(shard, frame), shard.inputsHash, false);
        if (check.status != FrameCheck::Status::Good)
            throw FileError(shard.folder.path(), check.detail +
                                                     ": simulate the shard again (vfield simulate SCENE -o OUT --shard " +
                                                     shard.part.text() + ")");
        parts[s] = readParticleGrid(*shard.folder.readParticles(frame, shard.inputsHash));
    });
    ParticleSet all = std::move(parts.front());
    for (std::size_t s = 1; s < parts.size(); ++s) all.append(parts[s]);
    all.sortById();
    BBoxd box;
    for (const Vec3f& p : all.position) box.expand(Vec3d(p));
    all.sortSpatially(box);
    return all;
}

} // namespace

SimulateSummary mergeShards(const Scene& scene, const std::string& outputDir, int count, const SimulateOptions& options)
{
    const SimulationSettings& setup = scene.simulation;
    const std::pair<int, int> frames = framesToWrite(setup, options);
    const int writeFirst = frames.first, writeLast = frames.second;
    if (count < 1) throw ValueError("a merge needs at least one shard");
    const auto preparing = [&](const std::string& step) {
        if (options.preparing) options.preparing(step);
    };

    preparing("reading the records of the objects and of " + std::to_string(count) + " shards");
    const uint64_t inputsHash = simulationInputsHash(setup, scene.volume);
    const PartRecords objects = readPart(ShardPart::objects(), outputDir, inputsHash, writeLast);
    std::vector<PartRecords> shards;
    for (int i = 0; i < count; ++i) shards.push_back(readPart({i, count}, outputDir, inputsHash, writeLast));

    const FolderLock lock(outputDir, "vfield simulate --merge", options.waitForFolder);
    const SimFolder folder(outputDir);
    // A merge's state holds no simulator state: there is none to resume, only frames to keep.
    RunState run;
    run.scenePath = fs::weakly_canonical(scene.path).string();
    run.inputsHash = inputsHash;
    SimulateSummary summary;
    if (folder.hasRunState()) {
        RunState saved = folder.readRunState();
        if (saved.scenePath != run.scenePath)
            throw FileError(outputDir,
                            "holds a simulation of another scene (" + saved.scenePath + "): use another folder or remove it");
        if (!saved.simulatorState.empty())
            throw FileError(outputDir, "holds a simulation run whole: merge into another folder or remove it");
        if (saved.inputsHash == run.inputsHash) {
            // Keep the frames merged before, up to the first that is not as written.
            preparing("checking the " + std::to_string(saved.records.size()) + " frames an earlier merge wrote");
            for (const FrameRecord& r : saved.records) {
                if (r.files && folder.checkFrame(r, run.inputsHash).status != FrameCheck::Status::Good) break;
                run.records.push_back(r);
            }
            if (!run.records.empty()) summary.resumedAfterFrame = run.records.back().frame;
        } else {
            folder.clear();
            summary.restartedStale = true;
        }
    }
    if (!fs::exists(folder.fieldFile())) {
        preparing("copying the static field, " + folder.fieldFile());
        const std::string field = readFileBytes(objects.folder.fieldFile());
        writeTextAtomically(folder.fieldFile(), field);
    }
    const Tracks tracks = objects.folder.readTracks();

    const int firstToMerge = run.records.empty() ? objects.frames.begin()->first : run.records.back().frame + 1;
    const int total = std::max(0, writeLast - firstToMerge + 1);
    const Stopwatch runWatch;
    for (int frame = firstToMerge; frame <= writeLast; ++frame) {
        const Stopwatch frameWatch;
        std::vector<const FrameRecord*> shardRecords;
        for (const PartRecords& shard : shards) shardRecords.push_back(&recordOf(shard, frame));
        FrameRecord record = combinedRecord(recordOf(objects, frame), shardRecords);
        if (frame >= writeFirst) {
            Stopwatch stageWatch;
            const ParticleSet particles = gatherParticles(shards, frame);
            if (particles.size() != record.alive)
                throw FileError(folder.path(), "the shards' files of frame " + std::to_string(frame) + " hold " +
                                                   std::to_string(particles.size()) + " particles, their records " +
                                                   std::to_string(record.alive));
            record.stages.write += stageWatch.lap(); // reading the shards' files, as the files' stage
            record.files = writeFrameVolume(folder, frame, particles, scene.volume, run.inputsHash, record.stages);
        }
        record.seconds += frameWatch.seconds();
        summary.stages += record.stages;
        run.records.push_back(record);
        Tracks upToFrame = tracks;
        upToFrame.keepUpTo(frame);
        folder.writeStats({run.inputsHash, setup.fps, objects.fields, run.records});
        folder.writeTracks(upToFrame, setup.fps);
        run.tracks = upToFrame;
        folder.writeRunState(run); // last: marks the frame merged

        if (options.progress) {
            FrameProgress progress;
            progress.frame = frame;
            progress.done = frame - firstToMerge + 1;
            progress.total = total;
            progress.alive = record.alive;
            progress.elapsedSeconds = runWatch.seconds();
            options.progress(progress);
        }
    }
    writeHostScene(scene, folder);
    summary.addFrames(run.records);
    return summary;
}

} // namespace vfield
