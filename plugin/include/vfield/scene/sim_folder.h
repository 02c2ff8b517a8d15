#pragma once
/// @file sim_folder.h
/// A simulation folder, the one place that knows its files' names and reads
/// and writes them (their formats: tracks.h, stats_file.h, run_state.h): what
/// `vfield simulate` writes and what renderers, `export-mesh` and hosts read.
///   field.vdb            the static objects' combined `force` grid, world space
///   density.####.vdb     `density` (FloatGrid) and `vel` (Vec3SGrid), world space
///   particles.####.vdb   `particles` (PointDataGrid: P, v, id, pscale)
///   tracks.json          per frame, each dynamic object's pose and velocity (Tracks)
///   stats.json           per frame, particles alive and removed, substeps, clearances (FrameRecord)
///   state.bin            the state after the last complete frame, to resume from (RunState)
/// Every file is written atomically.

#include <vfield/scene/run_state.h>
#include <vfield/scene/stats_file.h>
#include <vfield/scene/tracks.h>
#include <vfield/volume/density_splat.h>

#include <openvdb/openvdb.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace vfield {

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
