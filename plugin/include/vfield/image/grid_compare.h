#pragma once
/// @file grid_compare.h
/// Two OpenVDB files compared by content, grid by grid (matched by name):
/// float and vector grids voxel by voxel within a tolerance, over the union of
/// their active voxels; other grids (points) must hash equal (gridChecksum).

#include <cstdint>
#include <string>
#include <vector>

namespace vfield {

struct GridDifference {
    std::string name, type;
    uint64_t voxels = 0;         ///< active in either file
    uint64_t differing = 0;      ///< of those, differing by more than the tolerance (or active in one file only)
    double maxDifference = 0;    ///< largest absolute difference (vector length for vector grids)
    bool comparedByHash = false; ///< a grid type compared only for exact equality
};

struct GridComparison {
    std::vector<GridDifference> grids;         ///< the grids both files hold
    std::vector<std::string> onlyInA, onlyInB; ///< grid names in one file only
    bool equal() const;
};

/// Throws FileError when a file cannot be read.
GridComparison compareGridFiles(const std::string& pathA, const std::string& pathB, double tolerance = 0.0);

} // namespace vfield
