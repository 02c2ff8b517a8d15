#pragma once
/// @file sim_folder.h
/// A simulation folder, the one place that knows its files' names and reads
/// and writes them (their formats: tracks.h, stats_file.h, run_state.h): what
/// `vfield simulate` writes and what renderers, `export-mesh` and hosts read.
///   field.vdb            the static objects' combined `force` grid as particles read it, world space
///   density.####.vdb     `density` (FloatGrid) and `vel` (Vec3SGrid), world space
///   particles.####.vdb   `particles` (PointDataGrid: P, v, id, pscale)
///     each frame file carries, as file metadata, the inputs hash of the run
///     that wrote it (`vfield:inputsHash`, 16 hexadecimal digits) and its frame
///     (`vfield:frame`); stats.json records each one's size and a hash of its bytes
///   tracks.json          per frame, each dynamic object's pose and velocity (Tracks)
///   stats.json           per frame, particles alive and removed, substeps, clearances (FrameRecord)
///   state.bin            the state after the last complete frame, to resume from (RunState)
///   .vfield-lock         held by the one process writing the folder (FolderLock)
///   shards/              the parts of a sharded simulation, each a folder of these files (shard_part.h)
/// Every file is written atomically.

#include <vfield/core/fields.h>
#include <vfield/core/vdb_trees.h>
#include <vfield/folder/run_state.h>
#include <vfield/folder/stats_file.h>
#include <vfield/folder/tracks.h>
#include <vfield/volume/density_splat.h>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace vfield {

/// What a frame's files are, checked against what the folder recorded.
struct FrameCheck {
    enum class Status {
        Good,    ///< both files there, made by this folder's simulation, as written
        Missing, ///< a file is not there (or the frame was never written)
        Foreign, ///< a file was made by another simulation, or for another frame
        Corrupt  ///< a file is not as written: another size or other bytes, or unreadable
    };
    Status status = Status::Good;
    std::string detail; ///< for other than Good: the file and what is wrong with it
};
inline constexpr EnumName<FrameCheck::Status> kFrameCheckStatusNames[] = {{FrameCheck::Status::Good, "good"},
                                                                          {FrameCheck::Status::Missing, "missing"},
                                                                          {FrameCheck::Status::Foreign, "foreign"},
                                                                          {FrameCheck::Status::Corrupt, "corrupt"}};
constexpr const auto& enumNames(FrameCheck::Status) { return kFrameCheckStatusNames; }

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
    /// named `density`, every active value is finite, and it was made by the
    /// simulation whose inputs hash is given (when given). Throws FileError.
    openvdb::FloatGrid::Ptr readDensity(int frame, std::optional<uint64_t> inputsHash = std::nullopt) const;
    /// The density checked as readDensity checks it, and the `vel` grid
    /// beside it (null in a file without one).
    DensityGrids readDensityGrids(int frame, std::optional<uint64_t> inputsHash = std::nullopt) const;
    /// The frame's files against the record of them and the folder's inputs
    /// hash: their metadata always, their bytes with checkBytes.
    FrameCheck checkFrame(const FrameRecord& record, uint64_t inputsHash, bool checkBytes = true) const;
    /// tracks.json. Throws FileError when it is missing or unreadable.
    Tracks readTracks() const;
    StatsFile readStats() const;
    bool hasRunState() const;
    RunState readRunState() const;

    /// The frame's density file: the volume stage's `density` and `vel`
    /// grids, stamped with the simulation's inputs hash and the frame.
    /// Returns its fingerprint.
    FileFingerprint writeDensity(int frame, const DensityGrids& grids, uint64_t inputsHash) const;
    /// The frame's particle file (makeParticleGrid), stamped as writeDensity stamps it.
    FileFingerprint writeParticles(int frame, const openvdb::GridBase::Ptr& particles, uint64_t inputsHash) const;
    /// The frame's particle grid, checked as readDensity checks its grid.
    openvdb::GridBase::Ptr readParticles(int frame, uint64_t inputsHash) const;
    void writeTracks(const Tracks& tracks, double fps) const;
    void writeStats(const StatsFile& stats) const;
    /// Written last after a frame: marks it complete. The simulator's state
    /// is streamed from writeSimulatorState when given (writeRunState in run_state.h).
    void writeRunState(const RunState& state, const std::function<void(std::ostream&)>& writeSimulatorState = {}) const;
    /// Removes every file a simulation writes here (frames, tracks, stats,
    /// state, field), so that a fresh run leaves nothing stale behind.
    void clear() const;

private:
    std::string file(const std::string& name) const;
    std::string mPath;
};

} // namespace vfield
