#pragma once
/// @file simulation_run.h
/// Scene -> a simulation folder (sim_folder.h): the static field, density and
/// particle grids per frame, tracks, statistics, the state to resume from,
/// and what a host rebuilds the scene from (host/, host_scene.h).
///
/// One run writes a folder at a time (FolderLock): a second is refused at
/// once, or waits when asked to.
/// A run that finds a state of the same scene with the same inputs resumes
/// after its last complete frame and gives the same files as an uninterrupted
/// run. It first checks that every frame the earlier runs wrote is still there
/// as written (stamped with the same inputs hash, of the size and bytes
/// stats.json records): from the first that is not, it simulates again. If the scene file or a mesh it names was edited since,
/// the folder's files are stale: the run removes them and simulates afresh (and says so). A folder holding a simulation of
/// another scene file is refused.

#include <vfield/core/folder_lock.h>
#include <vfield/folder/sim_folder.h>
#include <vfield/run/shard_part.h>
#include <vfield/scene/scene.h>

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace vfield {

struct FrameProgress {
    int frame = 0;           ///< frame just finished
    int done = 0, total = 0; ///< frames finished in this run, and to finish
    uint64_t alive = 0;
    double elapsedSeconds = 0.0;
};

struct SimulateOptions {
    /// Options that write only frames first..last.
    static SimulateOptions writing(int first, int last)
    {
        SimulateOptions options;
        options.firstFrame = first;
        options.lastFrame = last;
        return options;
    }

    /// Frames to write, within the scene's range; earlier frames are simulated
    /// but not written. Unset: the scene's whole range.
    std::optional<int> firstFrame, lastFrame;
    /// Called after each frame (from the calling thread).
    std::function<void(const FrameProgress&)> progress;
    /// Called once the folder holds every frame to write, before the host
    /// scene is written: also when an earlier run had written them all, and
    /// `progress` was never called.
    std::function<void(int lastFrame)> finished;
    /// Told each step before the first frame as it starts: building the
    /// fields and exact distances (Simulator::Preparing, from worker threads,
    /// one call at a time), checking an earlier run's frames, writing the
    /// static field.
    std::function<void(const std::string& step)> preparing;
    /// Refuse, before loading anything, a scene estimated to need more memory
    /// than this (bytes; memory_estimate.h). Unset: the memory available now.
    std::optional<double> maxMemoryBytes;
    /// The folder has one writer at a time (FolderLock). When another process
    /// writes it, this is called with who, and the run waits for it; unset:
    /// the run is refused at once.
    FolderLock::Waiting waitForFolder;
    /// One part of a sharded simulation (shard_part.h), into its folder in
    /// the output folder; unset: the whole simulation, into the output folder.
    /// A shard needs the objects' part's tracks up to the frames it writes.
    std::optional<ShardPart> part;
};

struct SimulateSummary {
    std::vector<FrameRecord> frames; ///< every frame simulated so far, resumed ones included
    /// The last frame of an earlier run that this one kept, or -1: from the
    /// state it saved, and the frames it wrote after that state (stepped
    /// through again, not written).
    int resumedAfterFrame = -1;
    /// The first frame an earlier run wrote that was missing, foreign or
    /// corrupt, so that the run simulated it again (from the initial state,
    /// writing nothing before it), or -1; and what was wrong with it.
    int resimulatedFrom = -1;
    std::string resimulatedBecause;
    bool restartedStale = false;       ///< the folder held a run of an earlier edit of the scene
    std::vector<std::string> warnings; ///< e.g. open meshes whose inside is undefined
    ClearanceStats worstParticles;     ///< the particles' minima over all frames, penetrations summed
    /// Each pair of objects measured (a dynamic one first) at its closest over all frames.
    std::vector<PairClearance> closestPairs;
    uint64_t overlappingPairFrames = 0; ///< (pair, frame)s whose meshes overlapped
    uint64_t contacts = 0;              ///< particle contacts with dynamic objects, all frames (StepStats)
    uint64_t endedInside = 0;           ///< particle substeps that ended inside a dynamic object, all frames
    StageSeconds stages;                ///< the frames simulated by this run, summed

    /// Takes the records of every frame so far, with their totals above
    /// (clearances, pairs, contacts); stages stay this run's.
    void addFrames(const std::vector<FrameRecord>& records);
};

SimulateSummary simulateScene(const Scene& scene, const std::string& outputDir, const SimulateOptions& options = {});

/// The first and last frame a run with these options writes. Throws
/// ValueError when they are not within the scene's range.
std::pair<int, int> framesToWrite(const SimulationSettings& setup, const SimulateOptions& options);

} // namespace vfield
