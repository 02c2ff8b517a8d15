#include <vfield/sim/clearance.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace vfield {

namespace {

/// Trilinear reads of a level set change by at most sqrt(3) per unit of
/// distance (each axis's slope is at most 1): how far a value can drop
/// between a piece of triangle's centroid and its corners.
constexpr double kLipschitz = 1.7320508075688772;

/// The smallest of valueAt over the triangle abc (and best), to within what
/// changes over spacing: the triangle splits into four at its edges'
/// midpoints while a piece is longer than spacing and the value at its
/// centroid, less the most it can drop within the piece, could still beat
/// the best found. Only the pieces near the other surface are refined.
template<typename ValueAt>
double smallestOverTriangle(const Vec3d& a, const Vec3d& b, const Vec3d& c, double spacing, const ValueAt& valueAt, double best)
{
    const Vec3d centroid = (a + b + c) / 3.0;
    const double radius =
        std::sqrt(std::max({(a - centroid).lengthSqr(), (b - centroid).lengthSqr(), (c - centroid).lengthSqr()}));
    const double value = valueAt(centroid);
    best = std::min(best, value);
    if (value - kLipschitz * radius >= best) return best;
    if (std::max({(b - a).length(), (c - b).length(), (a - c).length()}) <= spacing) {
        for (const Vec3d& corner : {a, b, c}) best = std::min(best, valueAt(corner));
        return best;
    }
    const Vec3d ab = (a + b) * 0.5, bc = (b + c) * 0.5, ca = (c + a) * 0.5;
    best = smallestOverTriangle(a, ab, ca, spacing, valueAt, best);
    best = smallestOverTriangle(ab, b, bc, spacing, valueAt, best);
    best = smallestOverTriangle(ca, bc, c, spacing, valueAt, best);
    return smallestOverTriangle(ab, bc, ca, spacing, valueAt, best);
}

} // namespace

ClearanceProbe::ClearanceProbe(const Simulator& simulator) : mSimulator(simulator)
{
    for (std::size_t i = 0; i < simulator.objects().size(); ++i) {
        const SimObject& object = simulator.objects()[i];
        if (object.spec->isDynamic) {
            if (object.distance) mSurfaces.push_back({i, object.distance});
            else
                mWarnings.push_back("object \"" + object.spec->name +
                                    "\" is not a closed mesh: particles and objects are not measured against it");
            continue;
        }
        if (!object.isClosed)
            mWarnings.push_back("object \"" + object.spec->name +
                                "\" is not a closed mesh: its inside is undefined, so signed distances to it may be wrong");
        mSurfaces.push_back({i, object.distance});
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
    stats.mean = std::accumulate(d.begin(), d.end(), 0.0) / double(d.size()); // in order: thread-independent
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

ClearanceProbe::Reading ClearanceProbe::surfaceToSurface(std::size_t from, const Surface& to) const
{
    const SimObject& object = mSimulator.objects()[from];
    const Transform& fromPose = mSimulator.objectStates()[from].pose;
    const Transform& toPose = mSimulator.objectStates()[to.object].pose;
    const MeshDistance& distance = *to.distance;
    const BBoxd reach = toPose.worldBounds(distance.reach());
    const double spacing = distance.voxelSize() * toPose.scale;
    const std::size_t n = object.mesh.triangleCount();
    const double band = distance.exteriorBand() * toPose.scale, exactBelow = 0.5 * band;
    // Apart: nothing to refine (measured every substep, so worth the check).
    if (n == 0 || !fromPose.worldBounds(object.mesh.bounds()).hasOverlap(reach)) return {exactBelow, exactBelow};
    // Two passes, so that the result does not depend on the threads' order:
    // the corners give a bound that every triangle's refinement then only
    // has to beat (far triangles stop at their centroid). Distances from half
    // the band out are not refined: proving that no point of a triangle comes
    // nearer than the band itself would refine every piece within it.
    const auto forEachTriangleInReach = [&](const auto& measure) {
        std::vector<double> nearest(n, exactBelow);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const auto& range) {
            MeshDistance::Accessor accessor = distance.accessor();
            const auto valueAt = [&](const Vec3d& p) {
                const Vec3d local = toPose.objectFromWorld(p);
                return distance.reach().isInside(local) ? distance.distance(accessor, local) * toPose.scale : band;
            };
            for (std::size_t t = range.begin(); t != range.end(); ++t) {
                const openvdb::Vec3I& tri = object.mesh.triangles[t];
                Vec3d corner[3];
                BBoxd box;
                for (int c = 0; c < 3; ++c) box.expand(corner[c] = fromPose.worldFromObject(Vec3d(object.mesh.points[tri[c]])));
                if (box.hasOverlap(reach)) nearest[t] = measure(corner, valueAt);
            }
        });
        return *std::min_element(nearest.begin(), nearest.end());
    };
    const double atCorners = forEachTriangleInReach([&](const Vec3d* corner, const auto& valueAt) {
        return std::min({valueAt(corner[0]), valueAt(corner[1]), valueAt(corner[2]), exactBelow});
    });
    const double smallest = forEachTriangleInReach([&](const Vec3d* corner, const auto& valueAt) {
        return smallestOverTriangle(corner[0], corner[1], corner[2], spacing, valueAt, atCorners);
    });
    return {smallest, exactBelow};
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
            std::vector<Reading> readings;
            if (surfaceB) readings.push_back(surfaceToSurface(a, *surfaceB));
            // b's triangles in a's level set catch features of b finer than
            // a's sampling. Where a's points measured b farther than a's level
            // set is exact (by more than a sample spacing), b's could not
            // improve on it: skipped, as the terrain's many triangles cost.
            if (surfaceA) {
                const double exactInA = 0.5 * surfaceA->distance->exteriorBand() * mSimulator.objectStates()[a].pose.scale;
                const double slack = surfaceB ? surfaceB->distance->voxelSize() * mSimulator.objectStates()[b].pose.scale : 0.0;
                if (readings.empty() || !readings[0].exact() || readings[0].value <= exactInA + slack)
                    readings.push_back(surfaceToSurface(b, *surfaceA));
            }
            // The smallest exact reading; with none, the surfaces are at least
            // as far apart as the farthest either level set vouches for.
            double minimum = std::numeric_limits<double>::infinity(), atLeast = 0.0;
            for (const Reading& r : readings) {
                if (r.exact()) minimum = std::min(minimum, r.value);
                atLeast = std::max(atLeast, r.atLeast);
            }
            const bool exact = std::isfinite(minimum);
            pairs.push_back({objects[a].spec->name, objects[b].spec->name, exact ? minimum : atLeast, exact});
        }
    }
    return pairs;
}

void ClearanceStats::add(const ClearanceStats& other)
{
    if (other.samples == 0) return;
    if (samples == 0 || other.minimum < minimum) minimum = other.minimum;
    if (samples == 0 || other.percentile1 < percentile1) percentile1 = other.percentile1;
    mean = (mean * double(samples) + other.mean * double(other.samples)) / double(samples + other.samples);
    penetrations += other.penetrations;
    samples += other.samples;
}

} // namespace vfield
