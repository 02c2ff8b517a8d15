#include <vfield/volume/density_splat.h>

#include "deposit.h"
#include "detail_styles.h"

#include <vfield/core/field_visitors.h>
#include <vfield/core/stopwatch.h>

#include <openvdb/tools/Filter.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace vfield {

void VolumeSettings::validate() const
{
    checkFields(*this);
    if (voxelSize > 0.0 && kernelRadius > 0.0)
        require(kernelRadius / voxelSize <= kMaxKernelVoxels, "kernelRadius",
                "kernel radius " + numberText(kernelRadius) + " spans more than " + numberText(kMaxKernelVoxels) + " voxels of " +
                    numberText(voxelSize));
    if (voxelSize > 0.0 && detail.enabled() && detail.style == DetailStyle::Displaced)
        require(detail.displacementRange() / voxelSize <= kMaxDisplacementVoxels, "detail/amplitude",
                "the displaced surface moves over " + numberText(detail.displacementRange()) +
                    " world units (amplitude x (1 + gain + ...) / frequency), more than " + numberText(kMaxDisplacementVoxels) +
                    " voxels of " + numberText(voxelSize) + ": lower the amplitude or raise the frequency");
}

VolumeSettings VolumeSettings::resolved(double meanParticleRadius) const
{
    VolumeSettings r = *this;
    if (r.voxelSize == 0.0) r.voxelSize = meanParticleRadius;
    r.kernelRadius = std::max(r.kernelRadius > 0.0 ? r.kernelRadius : 2.0 * meanParticleRadius, r.voxelSize);
    return r;
}

namespace {

/// Variance along an axis, in voxels squared, of the smooth kernel of radius R
/// voxels, W(r) ~ (1 - r^2/R^2)^3: R^2 / 11.
double smoothKernelVariance(double radiusInVoxels) { return radiusInVoxels * radiusInVoxels / 11.0; }

/// Passes of a 3-voxel mean filter after the trilinear deposit (variance 1/6,
/// each pass adds 2/3) that bring the kernel's spread closest to that of the
/// smooth kernel of the given radius: at least one, so the kernel is four
/// voxels wide and smooth to trilinear reads.
int blurPasses(double radiusInVoxels)
{
    return std::max(1, int(std::lround((smoothKernelVariance(radiusInVoxels) - 1.0 / 6.0) * 1.5)));
}

/// The kernel's weight at its centre, per axis, for a particle at a voxel
/// centre: the middle of [1 1 1]/3 convolved with itself `passes` times.
double centreWeight(int passes)
{
    std::vector<double> weights{1.0};
    for (int pass = 0; pass < passes; ++pass) {
        std::vector<double> next(weights.size() + 2, 0.0);
        for (std::size_t i = 0; i < weights.size(); ++i)
            for (std::size_t j = 0; j < 3; ++j) next[i + j] += weights[i] / 3.0;
        weights = std::move(next);
    }
    return weights[weights.size() / 2];
}

/// OpenVDB's mean filter, `passes` times, over the grid's voxels grown by
/// as many voxels: the blur reaches every voxel it can give a value to.
template<typename GridT>
void blur(GridT& grid, int passes)
{
    openvdb::tools::dilateActiveValues(grid.tree(), passes, openvdb::tools::NN_FACE_EDGE_VERTEX, openvdb::tools::IGNORE_TILES);
    openvdb::tools::Filter<GridT> filter(grid);
    filter.mean(1, passes);
}

/// Deactivates every voxel below threshold, its value set to the background
/// (so that files need not store it), and prunes the leaves left empty.
void leaveOutBelow(openvdb::FloatGrid& grid, float threshold)
{
    // The voxels on the faces of the active box stay, so that the grid keeps
    // its bounds: what is placed by them (a renderer's light lattice, a
    // host's bounding box) does not move.
    const openvdb::CoordBBox bounds = grid.evalActiveVoxelBoundingBox();
    const auto onFace = [&bounds](const openvdb::Coord& c) {
        for (int axis = 0; axis < 3; ++axis)
            if (c[axis] == bounds.min()[axis] || c[axis] == bounds.max()[axis]) return true;
        return false;
    };
    openvdb::tree::LeafManager<openvdb::FloatTree> leaves(grid.tree());
    leaves.foreach ([&](openvdb::FloatTree::LeafNodeType& leaf, std::size_t) {
        for (auto it = leaf.beginValueOn(); it; ++it)
            if (*it < threshold && !onFace(it.getCoord())) leaf.setValueOff(it.pos(), 0.0f);
    });
    openvdb::tools::pruneInactive(grid.tree());
}

/// Leaves out the velocities where there is no density (of no use to a
/// host), their values the background so that they cost no bytes. The
/// density may be finer than the velocity (its detail): a velocity voxel is
/// kept when any density voxel it overlaps is.
void keepWhereActive(openvdb::Vec3SGrid& velocity, const openvdb::FloatGrid& density)
{
    openvdb::tree::LeafManager<openvdb::Vec3STree> leaves(velocity.tree());
    leaves.foreach ([&](openvdb::Vec3STree::LeafNodeType& leaf, std::size_t) {
        const auto kept = density.getConstAccessor();
        for (auto it = leaf.beginValueOn(); it; ++it) {
            const openvdb::Vec3d centre = it.getCoord().asVec3d();
            const openvdb::Vec3d lo = density.worldToIndex(velocity.indexToWorld(centre - 0.5)),
                                 hi = density.worldToIndex(velocity.indexToWorld(centre + 0.5));
            // Density voxels whose centres lie within the velocity voxel.
            const openvdb::CoordBBox overlap(openvdb::Coord::ceil(lo - 0.5 + 1e-6), openvdb::Coord::floor(hi + 0.5 - 1e-6));
            bool any = false;
            for (auto c = overlap.begin(); c && !any; ++c) any = kept.isValueOn(*c);
            if (!any) leaf.setValueOff(it.pos(), openvdb::Vec3s(0.0f));
        }
    });
    openvdb::tools::pruneInactive(velocity.tree());
}

} // namespace

DensityGrids splatParticles(const ParticleSet& particles, const VolumeSettings& options, SplatSeconds* seconds)
{
    const Stopwatch watch;
    const VolumeSettings resolved = options.resolved(meanRadius(particles));
    resolved.validate();
    const double voxel = resolved.voxelSize;
    const int passes = blurPasses(resolved.kernelRadius / voxel);
    const double perWeight = resolved.densityPerParticle / (voxel * voxel * voxel); // density of a unit weight
    // The rest positions the detail is drawn at, those with a weight.
    std::vector<RestChannel> channels;
    if (resolved.detail.enabled()) {
        const bool dual = particles.rest2.size() == particles.size();
        const float weight2 = dual ? std::clamp(particles.rest2Weight, 0.0f, 1.0f) : 0.0f;
        if (weight2 < 1.0f)
            channels.push_back(
                {particles.rest.size() == particles.size() ? &particles.rest : &particles.position, 1.0f - weight2});
        if (weight2 > 0.0f) channels.push_back({&particles.rest2, weight2, openvdb::Vec3f(131.7f, -71.3f, 217.9f)});
    }

    const auto transform = openvdb::math::Transform::createLinearTransform(voxel);
    Deposit total = depositParticles(particles, channels, resolved.condensation, transform);

    // The sums blurred: the kernel is the trilinear weights blurred, and the
    // means (velocity, rest) are of the blurred weights.
    blur(*total.weight, passes);
    blur(*total.momentum, passes);
    for (const openvdb::Vec3SGrid::Ptr& rest : total.rests) blur(*rest, passes);

    DensityGrids grids;
    grids.density = openvdb::FloatGrid::create(0.0f);
    grids.density->setTransform(transform->copy());
    grids.velocity = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    grids.velocity->setTransform(transform->copy());
    // The mean rest positions: the rest sums over the weights, in place.
    const std::vector<openvdb::Vec3SGrid::Ptr>& restMeans = total.rests;
    for (const auto& rest : restMeans) {
        const auto weight = total.weight->getConstAccessor();
        for (auto it = rest->beginValueOn(); it; ++it) {
            const float w = weight.getValue(it.getCoord());
            it.setValue(w > 0.0f ? *it / w : openvdb::Vec3s(0.0f));
        }
    }

    auto density = grids.density->getAccessor();
    auto velocity = grids.velocity->getAccessor();
    auto momentum = total.momentum->getConstAccessor();
    for (auto it = total.weight->cbeginValueOn(); it; ++it) {
        const float w = *it;
        if (!(w > 0.0f)) continue;
        density.setValue(it.getCoord(), float(perWeight * w));
        velocity.setValue(it.getCoord(), momentum.getValue(it.getCoord()) / w);
    }
    // The peak density of one lone particle: the scale of the edges and of the cutoff.
    const double lonePeak = perWeight * std::pow(centreWeight(passes), 3);
    const double splatDone = watch.seconds();
    if (!channels.empty()) {
        const double softness = resolved.detail.edgeSoftness > 0.0 ? resolved.detail.edgeSoftness : lonePeak;
        grids.density = resolved.detail.style == DetailStyle::Displaced
                            ? displacedDensity(*grids.density, restMeans, channels, resolved.detail, softness)
                            : detailedDensity(*grids.density, restMeans, channels, resolved.detail, softness);
    }
    if (resolved.cutoff > 0.0) {
        leaveOutBelow(*grids.density, float(resolved.cutoff * lonePeak));
        keepWhereActive(*grids.velocity, *grids.density);
    }
    grids.density->setName("density");
    grids.density->setGridClass(openvdb::GRID_FOG_VOLUME);
    grids.velocity->setName("vel");
    grids.velocity->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    grids.density->setSaveFloatAsHalf(options.densityPrecision == GridPrecision::Half);
    grids.velocity->setSaveFloatAsHalf(options.velocityPrecision == GridPrecision::Half);
    if (seconds) *seconds = {splatDone, watch.seconds() - splatDone};
    return grids;
}

} // namespace vfield
