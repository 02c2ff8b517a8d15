#pragma once
/// @file vdb_file.h
/// OpenVDB files as vfield writes and reads them: written atomically, read
/// whole (no lazy memory mapping of files that may be replaced) and checked,
/// summarized, and hashed by content so that two runs can be compared although
/// OpenVDB stamps every file with a random id.

#include <vfield/core/math.h>
#include <vfield/core/vdb_trees.h>

#include <cstdint>
#include <string>

namespace vfield {

/// Writes the grids to path (temporary name, then rename), with the file's
/// own metadata (what made it, beside the grids' own).
void writeVdb(const std::string& path, const openvdb::GridPtrVec& grids, const openvdb::MetaMap& fileMetadata = {});

/// Reads every grid of the file, and its file metadata when asked. Throws
/// FileError for a missing, unreadable or corrupt file, or one without grids.
openvdb::GridPtrVec readVdb(const std::string& path, openvdb::MetaMap* fileMetadata = nullptr);

/// The file's metadata alone, without reading its grids. Throws FileError
/// for a missing or unreadable file.
openvdb::MetaMap readVdbMetadata(const std::string& path);

/// What `vfield info` prints of a grid.
struct GridSummary {
    std::string name;
    std::string type;      ///< OpenVDB's type name, e.g. "vec3s"
    Vec3d voxelSize;       ///< world units
    uint64_t activeVoxels; ///< active voxels, tiles counted by their voxels
    BBoxd worldBounds;     ///< world-space box of the active voxels (empty grid: empty box)
    uint64_t memoryBytes;  ///< in-core size of the tree
};
GridSummary summarizeGrid(const openvdb::GridBase& grid);

/// A 64-bit hash of a grid's name, type, transform, background, active
/// topology and active values. Equal for equal contents, whatever the file id.
/// Throws ValueError for a grid type it cannot read.
uint64_t gridChecksum(const openvdb::GridBase& grid);

} // namespace vfield
