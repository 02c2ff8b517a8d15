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
#include <optional>

namespace fs = std::filesystem;

namespace vfield {

namespace {

void accumulate(ClearanceStats& worst, const ClearanceStats& frame)
{
    if (frame.samples == 0) return;
    if (worst.samples == 0 || frame.minimum < worst.minimum) worst.minimum = frame.minimum;
    if (worst.samples == 0 || frame.percentile1 < worst.percentile1) worst.percentile1 = frame.percentile1;
    worst.mean =
        (worst.mean * double(worst.samples) + frame.mean * double(frame.samples)) / double(worst.samples + frame.samples);
    worst.penetrations += frame.penetrations;
    worst.samples += frame.samples;
}

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
/// longer as written (missing, foreign or corrupt). Frames are checked in
/// parallel: it reads their bytes.
std::optional<BadFrame> firstBadFrame(const SimFolder& folder, const RunState& run, int writeFirst)
{
    std::vector<FrameCheck> checks(run.records.size());
    tbb::parallel_for(std::size_t(0), run.records.size(), [&](std::size_t i) {
        if (run.records[i].frame >= writeFirst) checks[i] = folder.checkFrame(run.records[i], run.inputsHash);
    });
    for (std::size_t i = 0; i < checks.size(); ++i)
        if (checks[i].status != FrameCheck::Status::Good) return BadFrame{run.records[i].frame, checks[i]};
    return std::nullopt;
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

    // Before anything is written or built: a scene too large is refused at once.
    const std::optional<double> limit = options.maxMemoryBytes ? options.maxMemoryBytes : availableMemory();
    if (limit) {
        try {
            requireMemoryWithin(estimateSimulationMemory(scene), *limit,
                                options.maxMemoryBytes ? "the limit" : "the memory available");
        } catch (const OptionError& e) {
            throw FileError(scene.path, e.what());
        }
    }

    const FolderLock lock(outputDir, "vfield simulate", options.waitForFolder);
    const SimFolder folder(outputDir);

    const auto preparing = [&](const std::string& step) {
        if (options.preparing) options.preparing(step);
    };
    Simulator simulator(setup, preparing);
    const ClearanceProbe clearance(simulator);
    SimulateSummary summary;
    summary.warnings = simulator.meshReports();
    for (const std::string& warning : clearance.warnings()) summary.warnings.push_back(warning);

    // Resume after the last complete frame of an earlier run of this scene with
    // the same inputs; a run of an earlier edit of it is stale.
    RunState run;
    run.scenePath = fs::weakly_canonical(scene.path).string();
    run.inputsHash = simulationInputsHash(setup, scene.volume);
    if (folder.hasRunState()) {
        RunState saved = folder.readRunState();
        if (saved.scenePath != run.scenePath)
            throw FileError(outputDir,
                            "holds a simulation of another scene (" + saved.scenePath + "): use another folder or remove it");
        if (saved.inputsHash == run.inputsHash) {
            run = std::move(saved);
            preparing("checking the " + std::to_string(run.records.size()) + " frames an earlier run wrote");
            const std::optional<BadFrame> bad = firstBadFrame(folder, run, writeFirst);
            if (!bad) {
                simulator.restoreState(run.simulatorState);
                if (simulator.frame() > writeLast)
                    throw ValueError("the output folder already holds frames up to " + std::to_string(simulator.frame()));
                summary.resumedAfterFrame = simulator.frame();
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
    if (!fs::exists(folder.fieldFile())) {
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
    for (bool first = !resumed; simulator.frame() < writeLast || first; first = false) {
        closestInFrame.clear();
        pairSeconds = 0.0;
        Stopwatch frameWatch, stageWatch;
        if (first) measurePairs(); // the initial poses; every later frame's last substep ends at it
        else simulator.advanceFrame(measurePairs);
        const int frame = simulator.frame();
        FrameRecord record;
        record.stages.advection = stageWatch.lap() - pairSeconds;
        record.frame = frame;
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
        for (const std::size_t i : dynamic) run.tracks.add(simulator.objects()[i].spec->name, frame, simulator.objectStates()[i]);
        if (frame >= writeFirst) {
            SplatSeconds splat;
            const DensityGrids volume = splatParticles(simulator.particles(), scene.volume, &splat);
            stageWatch.lap();
            record.stages.splat = splat.splat;
            record.stages.detail = splat.detail;
            record.files = folder.writeFrame(
                frame, volume, makeParticleGrid(simulator.particles(), scene.volume.particlePrecision), run.inputsHash);
            record.stages.write = stageWatch.lap();
        }
        record.seconds = frameWatch.seconds();
        summary.stages += record.stages;
        run.records.push_back(record);
        folder.writeStats({run.inputsHash, setup.fps, fields, run.records});
        folder.writeTracks(run.tracks, setup.fps);
        run.simulatorState = simulator.serializeState();
        folder.writeRunState(run); // last: marks the frame complete

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

    writeHostScene(scene, folder);
    summary.frames = run.records;
    for (const FrameRecord& r : summary.frames) {
        accumulate(summary.worstParticles, r.particleClearance);
        summary.contacts += r.contacts;
        summary.endedInside += r.endedInside;
        for (const PairClearance& pair : r.objectPairs) {
            if (pair.minimum < 0.0) ++summary.overlappingPairFrames;
            keepClosest(summary.closestPairs, pair);
        }
    }
    return summary;
}

} // namespace vfield
