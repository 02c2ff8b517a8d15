#include <vfield/sim/clearance.h>

#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace vfield {

ClearanceProbe::ClearanceProbe(const Simulator& simulator)
{
    for (std::size_t i = 0; i < simulator.objects().size(); ++i) {
        const SimObject& object = simulator.objects()[i];
        if (object.spec->isDynamic) continue;
        const BBoxd box = object.mesh.bounds();
        const double extent = box.extents()[box.maxExtent()];
        const double voxel = object.field ? 0.5 * object.field->finestCellSize() : extent / 256.0;
        const double reach = object.field ? 0.1 * object.field->rootSide() : 0.1 * extent;
        if (!analyzeTopology(object.mesh).isClosed())
            mWarnings.push_back("object \"" + object.spec->name +
                                "\" is not a closed mesh: its inside is undefined, so signed distances to it may be wrong");
        const auto transform = openvdb::math::Transform::createLinearTransform(voxel);
        std::vector<openvdb::Vec3I> triangles(object.mesh.triangles.begin(), object.mesh.triangles.end());
        LevelSet levelSet;
        // meshToLevelSet's sibling with separate exterior and interior bands.
        levelSet.grid = openvdb::tools::meshToSignedDistanceField<openvdb::FloatGrid>(
            *transform, object.mesh.points, triangles, {}, float(std::max(3.0, reach / voxel)), 3.0f);
        levelSet.pose = simulator.objectStates()[i].pose;
        mLevelSets.push_back(levelSet);
    }
}

double ClearanceProbe::distance(const Vec3d& world) const
{
    double nearest = std::numeric_limits<double>::infinity();
    for (const LevelSet& ls : mLevelSets) {
        const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sampler(*ls.grid);
        const double d = sampler.wsSample(ls.pose.objectFromWorld(world)) * ls.pose.scale;
        nearest = std::min(nearest, d);
    }
    return nearest;
}

ClearanceStats ClearanceProbe::measure(const std::vector<Vec3d>& points) const
{
    ClearanceStats stats;
    if (mLevelSets.empty() || points.empty()) return stats;
    std::vector<double> d(points.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 4096), [&](const auto& range) {
        std::vector<openvdb::FloatGrid::ConstAccessor> accessors;
        for (const LevelSet& ls : mLevelSets) accessors.push_back(ls.grid->getConstAccessor());
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            double nearest = std::numeric_limits<double>::infinity();
            for (std::size_t k = 0; k < mLevelSets.size(); ++k) {
                const LevelSet& ls = mLevelSets[k];
                const openvdb::Vec3d index = ls.grid->transform().worldToIndex(ls.pose.objectFromWorld(points[i]));
                float value;
                openvdb::tools::BoxSampler::sample(accessors[k], index, value);
                nearest = std::min(nearest, double(value) * ls.pose.scale);
            }
            d[i] = nearest;
        }
    });
    stats.samples = d.size();
    stats.penetrations = uint64_t(std::count_if(d.begin(), d.end(), [](double v) { return v < 0.0; }));
    const std::size_t k = d.size() / 100;
    std::nth_element(d.begin(), d.begin() + std::ptrdiff_t(k), d.end());
    stats.percentile1 = d[k];
    stats.minimum = *std::min_element(d.begin(), d.begin() + std::ptrdiff_t(k) + 1);
    return stats;
}

ClearanceStats ClearanceProbe::measureParticles(const ParticleSet& particles) const
{
    std::vector<Vec3d> points(particles.position.begin(), particles.position.end());
    return measure(points);
}

std::vector<Vec3d> ClearanceProbe::vertices(const SimObject& object, const Transform& pose)
{
    std::vector<Vec3d> points;
    points.reserve(object.mesh.points.size());
    for (const Vec3f& p : object.mesh.points) points.push_back(pose.worldFromObject(Vec3d(p)));
    return points;
}

} // namespace vfield
