#pragma once
/// @file detail_styles.h
/// Within libvfield's volume stage: the splat's density shaped by noise
/// drawn at the particles' rest positions, one function a style
/// (DetailStyle). Each returns the detailed density on the detail's finer
/// grid (fine_grid.h).

#include "fine_grid.h"

#include <vfield/core/vdb_trees.h>
#include <vfield/volume/volume_detail.h>

#include <vector>

namespace vfield {

/// The density resampled on the detail's finer grid and shaped by noise at
/// the interpolated rest position (DetailStyle::Erode and Billows).
openvdb::FloatGrid::Ptr detailedDensity(const openvdb::FloatGrid& density, const std::vector<openvdb::Vec3SGrid::Ptr>& rests,
                                        const std::vector<RestChannel>& channels, const DetailSettings& detail,
                                        double edgeSoftness);

/// DetailStyle::Displaced: the splat's surface, where its density is
/// edgeSoftness / 2, moved along its normal by billow noise: its coarse
/// octaves on the splat's grid, its fine ones on the detail's grid, only
/// within their own (smaller) range of the surface the coarse ones moved.
/// Split, as a single sum of all the octaves on the detail's grid would
/// visit every fine voxel within the whole range of the splat's surface and
/// draw every octave at each: several times the work.
openvdb::FloatGrid::Ptr displacedDensity(const openvdb::FloatGrid& density, const std::vector<openvdb::Vec3SGrid::Ptr>& rests,
                                         const std::vector<RestChannel>& channels, const DetailSettings& detail,
                                         double edgeSoftness);

} // namespace vfield
