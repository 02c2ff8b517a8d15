#include <vfield/sim/clearance.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace vfield {

ClearanceProbe::ClearanceProbe(const Simulator& simulator) : mSimulator(simulator)
{
    for (std::size_t i = 0; i < simulator.objects().size(); ++i) {
        const SimObject& object = simulator.objects()[i];
        const bool closed = analyzeTopology(object.mesh).isClosed();
        if (object.spec->isDynamic) {
            if (object.distance) mSurfaces.push_back({i, object.distance});
            else
                mWarnings.push_back("object \"" + object.spec->name +
                                    "\" is not a closed mesh: particles and objects are not measured against it");
            continue;
        }
        if (!closed)
            mWarnings.push_back("object \"" + object.spec->name +
                                "\" is not a closed mesh: its inside is undefined, so signed distances to it may be wrong");
        const BBoxd box = object.mesh.bounds();
        const double extent = box.extents()[box.maxExtent()];
        const double voxel = object.field ? 0.5 * object.field->finestCellSize() : extent / 256.0;
        const double reach = object.field ? 0.1 * object.field->rootSide() : 0.1 * extent;
        mSurfaces.push_back({i, std::make_shared<MeshDistance>(object.mesh, voxel, reach, 3.0 * voxel)});
    }
}

double ClearanceProbe::distance(const Vec3d& world) const
{
    double nearest = std::numeric_limits<double>::infinity();
    for (const Surface& surface : mSurfaces) {
        const Transform& pose = mSimulator.objectStates()[surface.object].pose;
        MeshDistance::Accessor accessor = surface.distance->accessor();
        nearest = std::min(nearest, surface.distance->distance(accessor, pose.objectFromWorld(world)) * pose.scale);
    }
    return nearest;
}

ClearanceStats ClearanceProbe::measure(const std::vector<Vec3d>& points) const
{
    ClearanceStats stats;
    if (mSurfaces.empty() || points.empty()) return stats;
    std::vector<double> d(points.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 4096), [&](const auto& range) {
        std::vector<MeshDistance::Accessor> accessors;
        for (const Surface& surface : mSurfaces) accessors.push_back(surface.distance->accessor());
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            double nearest = std::numeric_limits<double>::infinity();
            for (std::size_t k = 0; k < mSurfaces.size(); ++k) {
                const Transform& pose = mSimulator.objectStates()[mSurfaces[k].object].pose;
                const MeshDistance& distance = *mSurfaces[k].distance;
                const Vec3d local = pose.objectFromWorld(points[i]);
                // Beyond a level set's reach it reads as its band: a lower bound.
                const double d =
                    distance.reach().isInside(local) ? distance.distance(accessors[k], local) : distance.exteriorBand();
                nearest = std::min(nearest, d * pose.scale);
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

ClearanceStats ClearanceProbe::measureParticles() const
{
    const ParticleSet& particles = mSimulator.particles();
    return measure(std::vector<Vec3d>(particles.position.begin(), particles.position.end()));
}

double ClearanceProbe::surfaceToSurface(std::size_t from, const Surface& to) const
{
    const SimObject& object = mSimulator.objects()[from];
    const Transform& fromPose = mSimulator.objectStates()[from].pose;
    const Transform& toPose = mSimulator.objectStates()[to.object].pose;
    const MeshDistance& distance = *to.distance;
    const BBoxd reach = toPose.worldBounds(distance.reach());
    const double spacing = distance.voxelSize() * toPose.scale;
    const std::size_t n = object.mesh.triangleCount();
    std::vector<double> nearest(n, distance.exteriorBand() * toPose.scale);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const auto& range) {
        MeshDistance::Accessor accessor = distance.accessor();
        for (std::size_t t = range.begin(); t != range.end(); ++t) {
            const openvdb::Vec3I& tri = object.mesh.triangles[t];
            Vec3d corner[3];
            BBoxd box;
            for (int c = 0; c < 3; ++c) box.expand(corner[c] = fromPose.worldFromObject(Vec3d(object.mesh.points[tri[c]])));
            if (!box.hasOverlap(reach)) continue;
            for (const Vec3d& p : trianglePoints(corner[0], corner[1], corner[2], spacing)) {
                const Vec3d local = toPose.objectFromWorld(p);
                if (distance.reach().isInside(local))
                    nearest[t] = std::min(nearest[t], distance.distance(accessor, local) * toPose.scale);
            }
        }
    });
    return n == 0 ? distance.exteriorBand() * toPose.scale : *std::min_element(nearest.begin(), nearest.end());
}

std::vector<PairClearance> ClearanceProbe::measureObjects() const
{
    const auto& objects = mSimulator.objects();
    const auto surfaceOf = [&](std::size_t object) -> const Surface* {
        for (const Surface& s : mSurfaces)
            if (s.object == object) return &s;
        return nullptr;
    };
    std::vector<PairClearance> pairs;
    for (std::size_t a = 0; a < objects.size(); ++a) {
        if (!objects[a].spec->isDynamic) continue;
        for (std::size_t b = 0; b < objects.size(); ++b) {
            // Each pair once: a dynamic object against every static one and every later dynamic one.
            if (b == a || (objects[b].spec->isDynamic && b < a)) continue;
            const Surface *surfaceA = surfaceOf(a), *surfaceB = surfaceOf(b);
            if (!surfaceA && !surfaceB) continue;
            double minimum = std::numeric_limits<double>::infinity();
            if (surfaceB) minimum = std::min(minimum, surfaceToSurface(a, *surfaceB));
            if (surfaceA) minimum = std::min(minimum, surfaceToSurface(b, *surfaceA));
            pairs.push_back({objects[a].spec->name, objects[b].spec->name, minimum});
        }
    }
    return pairs;
}

} // namespace vfield
