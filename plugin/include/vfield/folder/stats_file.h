#pragma once
/// @file stats_file.h
/// stats.json: how each object's field was made, and per frame what the
/// simulation did and measured (particles alive and removed, substeps,
/// contacts, clearances against every mesh, timings).

#include <vfield/core/math.h>
#include <vfield/sim/clearance.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace vfield {

/// How an object's repulsive field was made, as the last run built it.
struct FieldRecord {
    std::string object;
    std::string method;        ///< enumName(RepulsionMethod)
    double buildSeconds = 0.0; ///< wall clock, building and voxelizing
    uint64_t memoryBytes = 0;  ///< RepulsionField::memoryBytes()
    double finestCell = 0.0;   ///< world units
};

/// A file as its writer left it: its size and a hash of its bytes, so that a
/// later run sees a file replaced, truncated or damaged since.
struct FileFingerprint {
    uint64_t bytes = 0;
    uint64_t hash = 0; ///< ContentHash of the bytes
    bool operator==(const FileFingerprint& o) const { return bytes == o.bytes && hash == o.hash; }
};

/// The files a frame wrote.
struct FrameFiles {
    FileFingerprint density, particles; ///< density: none (0 bytes) in a shard's folder (shard_part.h)
};

/// Where a frame's wall-clock time went, seconds.
struct StageSeconds {
    double advection = 0.0; ///< moving particles and objects through the fields (contacts included)
    double clearance = 0.0; ///< measuring every particle and object pair against the meshes
    double splat = 0.0;     ///< the particles' density and velocity grids
    double detail = 0.0;    ///< the density's noise detail and cutoff
    /// the files: the frame's volume stage beyond the splat and the detail
    /// (the particle grid is built and written beside the splat: writeFrameVolume)
    double write = 0.0;
    StageSeconds& operator+=(const StageSeconds& o)
    {
        advection += o.advection;
        clearance += o.clearance;
        splat += o.splat;
        detail += o.detail;
        write += o.write;
        return *this;
    }
};

/// One frame's line of stats.json.
struct FrameRecord {
    int frame = 0;
    uint64_t alive = 0, removed = 0, substeps = 0, contacts = 0;
    uint64_t endedInside = 0; ///< particle substeps that ended inside a dynamic object (StepStats)
    uint32_t maxSubsteps = 0, dynamicSubsteps = 0;
    double maxRollChange = 0.0;             ///< degrees, the most any dynamic object rolled over the frame
    double seconds = 0.0;                   ///< wall clock of simulating, measuring and writing the frame
    StageSeconds stages;                    ///< where that time went
    ClearanceStats particleClearance;       ///< the particles against every object
    std::vector<PairClearance> objectPairs; ///< every dynamic object against every other: closest over the frame's substeps
    Vec3d centroid{0.0};                    ///< mean particle position, world units
    BBoxd bounds;                           ///< box of the particles (empty without particles)
    std::optional<FrameFiles> files;        ///< what it wrote; none for a frame simulated but not written
};

/// stats.json.
struct StatsFile {
    uint64_t inputsHash = 0; ///< of the simulation that wrote the folder (inputs_hash.h)
    double fps = 24.0;
    std::vector<FieldRecord> fields;
    std::vector<FrameRecord> frames;
};

std::string statsJsonText(const StatsFile& stats);
/// Reads stats.json text (path names it in errors). Throws FileError.
StatsFile statsFromJsonText(const std::string& text, const std::string& path);

/// The frames' records alone, as a run state keeps them.
std::string frameRecordsJsonText(const std::vector<FrameRecord>& records);
/// Throws FileError naming path.
std::vector<FrameRecord> frameRecordsFromJsonText(const std::string& text, const std::string& path);

} // namespace vfield
