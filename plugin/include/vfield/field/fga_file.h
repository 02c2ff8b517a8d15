#pragma once
/// @file fga_file.h
/// OctreeField -> FGA, the "Fluid Grid ASCII" vector-field format that Unreal
/// Engine imports (and PopcornFX, VectorayGen): comma-separated text, the grid
/// size, the minimum corner, the maximum corner, then one vector per cell, x
/// fastest, then y, then z. A line per vector.

#include <vfield/core/math.h>
#include <vfield/field/octree_field.h>

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace vfield {

/// A dense grid of vectors over a box, cell (i, j, k) at
/// values[i + size[0] * (j + size[1] * k)], its centre at
/// bounds.min + (i + 0.5, j + 0.5, k + 0.5) x the cell's extent.
struct VectorGrid {
    std::array<int, 3> size{0, 0, 0};
    BBoxd bounds;
    std::vector<Vec3f> values;

    Vec3d cellCenter(int i, int j, int k) const;
};

/// The field sampled at the centres of `cells` x `cells` x `cells` cells over
/// its root cube (1..1024; the octree's finest cells when cells is
/// 2^(depth - 1)). Object space.
VectorGrid sampleField(const OctreeField& field, int cells);

/// Writes the grid as FGA (atomically). Throws FileError.
void writeFga(const std::string& path, const VectorGrid& grid);
/// Reads an FGA file. Throws FileError naming the file and the value where
/// it is malformed or holds fewer vectors than its size says.
VectorGrid readFga(const std::string& path);

} // namespace vfield
