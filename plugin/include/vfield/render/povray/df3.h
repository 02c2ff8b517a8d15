#pragma once
/// @file df3.h
/// A density grid as a POV-Ray density file (.df3): a dense box of 16-bit
/// samples, x fastest, then y, then z, big-endian, after a header of the three
/// sizes. POV-Ray reads a sample as value / 65535 over the unit cube, so the
/// file comes with where the cube sits in the world and what 65535 stands for.

#include <vfield/core/math.h>
#include <vfield/core/vdb_trees.h>

#include <cstdint>
#include <string>
#include <vector>

namespace vfield {

struct Df3Placement {
    /// The unit cube of the file, in world space, as POV-Ray reads it: sample
    /// i at i/n along each axis (its trilinear interpolation runs from sample
    /// i to i + 1, wrapping after the last), so the cube starts at sample 0's
    /// position and reaches one cell past the last sample's.
    BBoxd worldBounds;
    double densityScale = 0; ///< density = value / 65535 * densityScale (0 for an empty grid)
    double cellSize = 0;     ///< world units per sample along each axis
};

struct Df3Volume {
    int nx = 0, ny = 0, nz = 0;
    std::vector<uint16_t> values; ///< x fastest, then y, then z
    uint16_t at(int x, int y, int z) const { return values[(std::size_t(z) * ny + y) * nx + x]; }
};

/// Samples the density over the bounding box of its active voxels, grown by
/// one empty cell on each side so the medium fades to zero inside the box, and
/// writes it to path atomically. Samples lie at the cells' centres; at the grid's
/// own voxel size they are the voxels' values, exactly. Where an axis would
/// need more than maxResolution cells the cells grow by a whole factor and
/// sample the grid trilinearly. Throws ValueError for a grid that is not
/// axis-aligned with cubic voxels, FileError when the file cannot be written.
Df3Placement writeDf3(const openvdb::FloatGrid& density, const std::string& path, int maxResolution = 512);

/// Reads a .df3 file (8- or 16-bit samples become 16-bit). Throws FileError.
Df3Volume readDf3(const std::string& path);

} // namespace vfield
