#pragma once
/// @file sim_folder.h
/// A simulation folder, the one place that knows its files: what
/// `vfield simulate` writes and what renderers, `export-mesh` and hosts read.
///   field.vdb            the static objects' combined `force` grid, world space
///   density.####.vdb     `density` (FloatGrid) and `vel` (Vec3SGrid), world space
///   particles.####.vdb   `particles` (PointDataGrid: P, v, id, pscale)
///   tracks.json          per frame, each dynamic object's pose and velocity (Tracks)
///   stats.json           per frame, particles alive and removed, substeps, clearances (FrameRecord)
///   state.bin            the state after the last complete frame, to resume from (RunState)
/// Every file is written atomically.

#include <vfield/sim/clearance.h>
#include <vfield/sim/simulator.h>
#include <vfield/volume/density_splat.h>

#include <openvdb/openvdb.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace vfield {

/// One dynamic object's state at one frame, as tracks.json holds it.
struct TrackEntry {
    int frame = 0;
    Transform pose;      ///< position (the pivot, world) and orientation; scale is the scene's
    Vec3d velocity{0.0}; ///< world units / s
};

/// Per dynamic object (by name), its track over the frames simulated.
class Tracks {
public:
    void add(const std::string& object, int frame, const DynamicState& state);
    const std::map<std::string, std::vector<TrackEntry>>& objects() const { return mObjects; }
    /// The object's pose at frame. Throws FileError (naming the file it was
    /// read from) when the track holds no such entry.
    Transform pose(const std::string& object, int frame) const;
    /// The object's poses from the first frame of its track through frame, in
    /// frame order: the path a following camera rides. Throws as pose() does.
    std::vector<Transform> path(const std::string& object, int frame) const;

    /// tracks.json's text; fps is recorded beside the tracks.
    std::string toJsonText(double fps) const;
    /// Reads tracks.json text (path names it in errors). Throws FileError.
    static Tracks fromJsonText(const std::string& text, const std::string& path);

private:
    friend class SimFolder; // the run state keeps tracks too
    std::string mPath;      ///< where it was read from, for messages
    std::map<std::string, std::vector<TrackEntry>> mObjects;
};

/// One frame's line of stats.json.
/// How an object's repulsive field was made, as the last run built it.
struct FieldRecord {
    std::string object;
    std::string method;        ///< repulsionMethodName()
    double buildSeconds = 0.0; ///< wall clock, building and voxelizing
    uint64_t memoryBytes = 0;  ///< RepulsionField::memoryBytes()
    double finestCell = 0.0;   ///< world units
};

struct FrameRecord {
    int frame = 0;
    uint64_t alive = 0, removed = 0, substeps = 0, contacts = 0;
    uint64_t endedInside = 0; ///< particle substeps that ended inside a dynamic object (StepStats)
    uint32_t maxSubsteps = 0, dynamicSubsteps = 0;
    double maxRollChange = 0.0;             ///< degrees, the most any dynamic object rolled over the frame
    double seconds = 0.0;                   ///< wall clock of simulating and measuring the frame
    ClearanceStats particleClearance;       ///< the particles against every object
    std::vector<PairClearance> objectPairs; ///< every dynamic object against every other: closest over the frame's substeps
    Vec3d centroid{0.0};                    ///< mean particle position, world units
    BBoxd bounds;                           ///< box of the particles (empty without particles)
};

/// stats.json as written by writeStats.
struct StatsFile {
    double fps = 24.0;
    std::vector<FieldRecord> fields;
    std::vector<FrameRecord> frames;
};

/// What a resumed run needs: the simulator's state after the last complete
/// frame, the records and tracks so far, and what made them: the scene file
/// and the hash of the simulation's inputs (simulationInputsHash).
struct RunState {
    std::string scenePath; ///< absolute
    uint64_t inputsHash = 0;
    std::string simulatorState;
    std::vector<FrameRecord> records;
    Tracks tracks;
};

/// A hash of everything a simulation's result depends on: the typed
/// simulation setup and volume options, and the bytes of every mesh file they
/// name. Editing any of them, a mesh file included, changes it; camera, sun,
/// sky and render settings do not enter it. Throws FileError for an
/// unreadable mesh file.
uint64_t simulationInputsHash(const SimulationSetup& setup, const VolumeOptions& volume);

class SimFolder {
public:
    explicit SimFolder(std::string path);
    const std::string& path() const { return mPath; }

    std::string fieldFile() const;
    std::string densityFile(int frame) const;
    std::string particlesFile(int frame) const;
    std::string tracksFile() const;
    std::string statsFile() const;
    std::string stateFile() const;

    /// The frame's density grid, checked: the file exists, holds a float grid
    /// named `density`, and every active value is finite. Throws FileError.
    openvdb::FloatGrid::Ptr readDensity(int frame) const;
    /// tracks.json. Throws FileError when it is missing or unreadable.
    Tracks readTracks() const;
    StatsFile readStats() const;
    bool hasRunState() const;
    RunState readRunState() const;

    void writeFrame(int frame, const DensityGrids& volume, const openvdb::GridBase::Ptr& particles) const;
    void writeTracks(const Tracks& tracks, double fps) const;
    /// stats.json: the fields as this run built them, then every frame's record.
    void writeStats(const std::vector<FrameRecord>& records, const std::vector<FieldRecord>& fields, double fps) const;
    /// Written last after a frame: marks it complete.
    void writeRunState(const RunState& state) const;
    /// Removes every file a simulation writes here (frames, tracks, stats,
    /// state, field), so that a fresh run leaves nothing stale behind.
    void clear() const;

private:
    std::string file(const std::string& name) const;
    std::string mPath;
};

} // namespace vfield
