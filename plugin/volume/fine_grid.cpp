#include "fine_grid.h"

#include <cmath>

namespace vfield {

/// How many detail voxels span one of the splat's.
int fineRatio(const openvdb::FloatGrid& density, double detailVoxelSize)
{
    return std::max(1, int(std::lround(density.voxelSize()[0] / detailVoxelSize)));
}

/// The transform of a grid `ratio` times finer than `density`'s: fine voxel
/// ratio c + k (k = 0..ratio-1) lies inside coarse voxel c, its centre at
/// c + (k - (ratio - 1) / 2) / ratio coarse voxels.
openvdb::math::Transform::Ptr finerTransform(const openvdb::FloatGrid& density, int ratio)
{
    const double fine = density.voxelSize()[0] / ratio;
    auto transform = openvdb::math::Transform::createLinearTransform(fine);
    transform->postTranslate(openvdb::Vec3d(-0.5 * (ratio - 1) * fine));
    return transform;
}

/// The active voxels of `grid`'s topology, in its index space.
openvdb::MaskGrid::Ptr topologyOf(const openvdb::FloatGrid& grid)
{
    openvdb::MaskGrid::Ptr mask = openvdb::MaskGrid::create(false);
    mask->setTransform(grid.transform().copy());
    mask->topologyUnion(grid);
    return mask;
}

/// Two independent noises blended with weights a and b have a standard
/// deviation sqrt(a^2 + b^2) of one: dividing by it keeps the contrast
/// through the blend of the rest channels.
float inverseBlendNorm(const std::vector<RestChannel>& channels)
{
    double weightNorm = 0.0;
    for (const RestChannel& channel : channels) weightNorm += double(channel.weight) * double(channel.weight);
    return float(1.0 / std::sqrt(weightNorm));
}

} // namespace vfield
