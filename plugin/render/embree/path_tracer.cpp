#include <vfield/render/embree/path_tracer.h>

#include <vfield/core/trilinear_sampler.h>
#include <vfield/render/embree/camera_samples.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace vfield {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// A unit vector at angle acos(cosTheta) from unit axis, turned by 2 pi u about it.
Vec3d aroundAxis(const Vec3d& axis, double cosTheta, double u)
{
    const Vec3d helper = std::abs(axis[0]) < 0.9 ? Vec3d(1, 0, 0) : Vec3d(0, 1, 0);
    const Vec3d tangent = axis.cross(helper).unitSafe(), bitangent = axis.cross(tangent);
    const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta)), phi = 2.0 * M_PI * u;
    return (tangent * (sinTheta * std::cos(phi)) + bitangent * (sinTheta * std::sin(phi)) + axis * cosTheta).unitSafe();
}

/// The cosine between the directions of propagation before and after
/// scattering, drawn from Henyey-Greenstein with eccentricity g.
double sampleHenyeyGreenstein(double g, double u)
{
    if (std::abs(g) < 1e-3) return 1.0 - 2.0 * u;
    const double s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    return std::clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
}

/// The largest extinction that a trilinear read of the density can give in
/// each cell of a grid over the cloud's box (cells kMajorantVoxels voxels
/// wide, wider where they would exceed kMaxMajorantCells), and a walk along a
/// ray through the cells (Amanatides and Woo's DDA), as pbrt-v4's majorant
/// grid: free paths are drawn cell by cell under a bound near the density
/// they cross, and skip the empty ones. Under one majorant for the whole box
/// they stepped through the empty air around a sparse cloud, and through its
/// thin parts, at the pace of its densest voxel.
class MajorantGrid {
public:
    static constexpr int kMajorantVoxels = 4;
    static constexpr std::size_t kMaxMajorantCells = std::size_t(1) << 22;

    MajorantGrid(const openvdb::FloatGrid& density, const BBoxd& box, double extinction) : mOrigin(box.min())
    {
        const double voxel = density.voxelSize()[0];
        for (mCell = kMajorantVoxels * voxel;; mCell *= 2.0) {
            for (int axis = 0; axis < 3; ++axis) mCells[axis] = std::max(1, int(std::ceil(box.extents()[axis] / mCell)));
            if (latticeSize(mCells) <= kMaxMajorantCells) break;
        }
        mMajorant.assign(latticeSize(mCells), 0.0f);
        // A value (a voxel, or a tile's voxels) reaches reads within a voxel of it.
        for (auto value = density.cbeginValueOn(); value; ++value) {
            if (*value <= 0.0f) continue;
            const openvdb::CoordBBox voxels = value.getBoundingBox();
            const Vec3d lo = density.indexToWorld(voxels.min()) - Vec3d(voxel),
                        hi = density.indexToWorld(voxels.max()) + Vec3d(voxel);
            std::array<int, 3> from, to;
            for (int axis = 0; axis < 3; ++axis) {
                from[axis] = std::clamp(int(std::floor((lo[axis] - mOrigin[axis]) / mCell)), 0, mCells[axis] - 1);
                to[axis] = std::clamp(int(std::floor((hi[axis] - mOrigin[axis]) / mCell)), 0, mCells[axis] - 1);
            }
            const float sigma = float(extinction * *value);
            for (int k = from[2]; k <= to[2]; ++k)
                for (int j = from[1]; j <= to[1]; ++j)
                    for (int i = from[0]; i <= to[0]; ++i) {
                        float& majorant = mMajorant[index(i, j, k)];
                        majorant = std::max(majorant, sigma);
                    }
        }
    }

    /// Calls segment(from, to, majorant) for the cells that origin + t dir
    /// (dir unit) crosses for t in [tMin, tMax) (within the box), in order,
    /// skipping cells with nothing in them, while it returns true.
    template<typename Segment>
    void walk(const Vec3d& origin, const Vec3d& dir, double tMin, double tMax, const Segment& segment) const
    {
        std::array<int, 3> cell, step;
        std::array<double, 3> next, delta;
        const Vec3d start = (origin + dir * tMin - mOrigin) / mCell;
        for (int axis = 0; axis < 3; ++axis) {
            cell[axis] = std::clamp(int(std::floor(start[axis])), 0, mCells[axis] - 1);
            if (dir[axis] == 0.0) {
                step[axis] = 0;
                next[axis] = delta[axis] = kInfinity;
                continue;
            }
            step[axis] = dir[axis] > 0.0 ? 1 : -1;
            const double boundary = mOrigin[axis] + (cell[axis] + (dir[axis] > 0.0 ? 1 : 0)) * mCell;
            next[axis] = (boundary - origin[axis]) / dir[axis];
            delta[axis] = mCell / std::abs(dir[axis]);
        }
        for (double t = tMin; t < tMax;) {
            const int axis = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
            const double exit = std::min(next[axis], tMax);
            const float majorant = mMajorant[index(cell[0], cell[1], cell[2])];
            if (majorant > 0.0f && exit > t && !segment(t, exit, double(majorant))) return;
            t = exit;
            cell[axis] += step[axis];
            if (cell[axis] < 0 || cell[axis] >= mCells[axis]) return;
            next[axis] += delta[axis];
        }
    }

private:
    std::size_t index(int i, int j, int k) const
    {
        return (std::size_t(k) * std::size_t(mCells[1]) + std::size_t(j)) * std::size_t(mCells[0]) + std::size_t(i);
    }

    Vec3d mOrigin;
    double mCell = 1.0;
    std::array<int, 3> mCells{1, 1, 1};
    std::vector<float> mMajorant; ///< extinction, 1 / world units
};

/// The cloud as paths see it: sigma_t = extinction x the density read
/// trilinearly, free paths drawn under the majorant grid's bounds.
class Medium {
public:
    /// Reads the density as the fast integrator's march does.
    using Density = TrilinearSampler<openvdb::FloatTree>;

    Medium(const CloudVolume* volume, const MediumSettings& settings) : mExtinction(settings.extinction)
    {
        if (!volume || volume->empty() || mExtinction <= 0.0) return;
        mLighting = &volume->lighting();
        mMajorants.emplace(mLighting->density(), mLighting->bounds(), mExtinction);
    }
    bool present() const { return mMajorants.has_value(); }
    Density density() const { return Density(mLighting->density().tree()); }

    /// Delta tracking along origin + t dir (dir unit), t in [tMin, tMax): the
    /// distance of the first real collision, if there is one.
    std::optional<double> collision(Density& density, const Vec3d& origin, const Vec3d& dir, double tMin, double tMax,
                                    SampleRandom& random) const
    {
        std::optional<double> hit;
        if (!present() || !mLighting->clip(origin, dir, tMin, tMax)) return hit;
        mMajorants->walk(origin, dir, tMin, tMax, [&](double from, double to, double majorant) {
            for (double t = from;;) {
                t -= std::log(1.0 - random.next()) / majorant;
                if (t >= to) return true;
                if (random.next() * majorant < sigmaT(density, origin + dir * t)) {
                    hit = t;
                    return false;
                }
            }
        });
        return hit;
    }

    /// Ratio tracking: an unbiased estimate of the transmittance along
    /// origin + t dir, t in [tMin, tMax).
    double transmittance(Density& density, const Vec3d& origin, const Vec3d& dir, double tMin, double tMax,
                         SampleRandom& random) const
    {
        double transmittance = 1.0;
        if (!present() || !mLighting->clip(origin, dir, tMin, tMax)) return transmittance;
        mMajorants->walk(origin, dir, tMin, tMax, [&](double from, double to, double majorant) {
            for (double t = from;;) {
                t -= std::log(1.0 - random.next()) / majorant;
                if (t >= to) return true;
                transmittance *= 1.0 - sigmaT(density, origin + dir * t) / majorant;
                if (transmittance < 0.1) { // Russian roulette: what survives carries the rest
                    if (random.next() < 0.5) {
                        transmittance = 0.0;
                        return false;
                    }
                    transmittance *= 2.0;
                }
            }
        });
        return transmittance;
    }

private:
    double sigmaT(Density& density, const Vec3d& p) const
    {
        return mExtinction * std::max(0.0f, density.atIndex(mLighting->density().transform().worldToIndex(p)));
    }

    const CloudLighting* mLighting = nullptr;
    double mExtinction;
    std::optional<MajorantGrid> mMajorants;
};

/// The reference's paths through a frame: one instance per tile or task (its
/// density sampler caches tree nodes and is not shared between threads).
class PathTracer {
public:
    /// How a vertex takes the sun's light through the cloud: by ratio
    /// tracking (unbiased), or as the fast integrator's march does (a few
    /// times cheaper; its single scattering is the reference's within 1-2%),
    /// surfaces' shadows on scattering points included.
    enum class SunThroughCloud { RatioTracking, AsTheMarch };

    PathTracer(const FrameToRender& f, const Medium& medium, SunThroughCloud sunThroughCloud = SunThroughCloud::RatioTracking)
        : mFrame(f), mSettings(*f.settings), mMedium(medium), mToSun(mSettings.sun.direction.unitSafe()),
          mSunRadiance(mSettings.sun.color * mSettings.sun.intensity), mSunThroughCloud(sunThroughCloud)
    {
        if (!medium.present()) return;
        mDensity.emplace(medium.density());
        if (sunThroughCloud == SunThroughCloud::AsTheMarch) mLight.emplace(*f.volume);
    }

    /// Where a path leaves its first vertex: the camera, or a point where it
    /// has just scattered in the cloud.
    enum class Start { Camera, Scattered };

    /// The radiance carried back along the path that leaves `origin` along
    /// `dir` (unit). From the camera, `seen` receives the first surface's
    /// depth, and the result is what the camera sees (the sky's glow, haze);
    /// from a scattering point, it is the light of the path's later vertices
    /// alone, weight 1 after that scattering.
    Vec3d radiance(Vec3d origin, Vec3d dir, Start start, SampleRandom& random, CameraSample* seen = nullptr)
    {
        const RenderSettings& s = mSettings;
        const bool fromCamera = start == Start::Camera;
        Vec3d radiance(0.0), weight(1.0);
        double firstDistance = -1.0; // of the camera ray's event; none: the sky
        for (int events = fromCamera ? 0 : 1;;) {
            const bool cameraRay = fromCamera && events == 0;
            SurfaceHit hit;
            bool isSurface = false;
            const std::optional<double> scatter = nextEvent(origin, dir, cameraRay, random, hit, isSurface);
            if (cameraRay) {
                if (isSurface && seen) seen->depth = float(hit.distance);
                if (scatter || isSurface) firstDistance = scatter ? *scatter : hit.distance;
            }
            if (scatter) {
                const Vec3d p = origin + dir * *scatter;
                weight *= s.medium.albedo;
                radiance += weight * mSunRadiance * (s.medium.phase(dir.dot(mToSun)) * sunAtScattering(p, random));
                if (++events >= s.integrator.maxBounces) break;
                dir = scatteredDirection(dir, random);
                origin = p;
            } else if (isSurface) {
                // Seen from the camera, the noise as fine as its pixel (as the fast integrator draws it).
                const SurfaceShading surface = cameraRay
                                                   ? surfaceShading(mFrame, hit,
                                                                    surfaceNoise(surfaceMaterial(mFrame, hit.object),
                                                                                 hit.position, pixelFootprint(mFrame, hit, dir)))
                                                   : surfaceShading(mFrame, hit);
                const Vec3d offset = hit.position + hit.geometricNormal * 1e-3 * (1.0 + hit.distance);
                const double cosSun = surface.normal.dot(mToSun);
                if (cosSun > 0.0)
                    radiance += weight * surface.albedo * mSunRadiance * (cosSun / M_PI * sunReaching(offset, random));
                weight *= surface.albedo;
                if (++events >= s.integrator.maxBounces) break;
                // Cosine-distributed about the shading normal: the weight keeps albedo alone.
                const double u = random.next();
                dir = aroundAxis(surface.normal, std::sqrt(u), random.next());
                if (dir.dot(hit.geometricNormal) <= 0.0) break; // into the surface: absorbed
                origin = offset;
            } else {
                // Escaped: the camera sees the sky with the sun's glow; light
                // paths find only the dome (the sun is sampled at every event).
                if (!cameraRay) radiance += weight * skyDomeRadiance(s.sky, dir);
                else if (!s.image.transparentSky) radiance = skyRadiance(s, dir);
                break;
            }
            if (events >= 3) { // Russian roulette on the path's weight
                const double survive = std::clamp(std::max({weight[0], weight[1], weight[2]}), 0.05, 1.0);
                if (random.next() >= survive) break;
                weight /= survive;
            }
        }
        if (!fromCamera) return radiance;
        if (seen) seen->alpha = firstDistance >= 0.0 || !s.image.transparentSky ? 1.0 : 0.0;
        return firstDistance >= 0.0 ? throughHaze(s.sky, radiance, firstDistance) : radiance;
    }

    /// A direction after scattering off the medium, drawn from its two-lobe phase function.
    Vec3d scatteredDirection(const Vec3d& dir, SampleRandom& random) const
    {
        const bool backLobe = random.next() < mSettings.medium.backWeight;
        const double g = backLobe ? mSettings.medium.backAnisotropy : mSettings.medium.anisotropy;
        const double cosTheta = sampleHenyeyGreenstein(g, random.next());
        return aroundAxis(dir, cosTheta, random.next());
    }

private:
    /// The first event along origin + t dir: a collision in the medium (its
    /// distance), or else the first surface (hit, isSurface), or neither.
    /// Within the cloud most free paths end before any surface, so after the
    /// camera ray the collision is drawn first and only the segment up to it
    /// is tested for a surface (any hit, bounded: a fraction of a full
    /// intersection's cost); delta tracking's tentative collisions do not
    /// depend on where it stops, so a surface before the collision is the
    /// same event as a walk stopped at the surface. The camera ray intersects
    /// first, for the depth of what it sees.
    std::optional<double> nextEvent(const Vec3d& origin, const Vec3d& dir, bool cameraRay, SampleRandom& random, SurfaceHit& hit,
                                    bool& isSurface)
    {
        if (cameraRay || !mDensity) {
            isSurface = mFrame.surfaces->intersect(origin, dir, 0.0, kInfinity, hit);
            if (!mDensity) return std::nullopt;
            return mMedium.collision(*mDensity, origin, dir, 0.0, isSurface ? hit.distance : kInfinity, random);
        }
        const std::optional<double> scatter = mMedium.collision(*mDensity, origin, dir, 0.0, kInfinity, random);
        if (scatter && !mFrame.surfaces->occluded(origin, dir, 0.0, *scatter)) return scatter;
        isSurface = mFrame.surfaces->intersect(origin, dir, 0.0, kInfinity, hit);
        return scatter && !(isSurface && hit.distance < *scatter) ? scatter : std::nullopt;
    }

    /// The sun's light reaching p, a scattering point in the cloud. Taken as
    /// the march takes it, surfaces' shadows come from CloudLighting's grid
    /// instead of a ray to the sun at every event, 4% of the benchmark's
    /// frame with paths at pathSpacing 4 (410 -> 395 ms, medians of five
    /// alternated runs).
    double sunAtScattering(const Vec3d& p, SampleRandom& random)
    {
        if (mSunThroughCloud == SunThroughCloud::AsTheMarch) return mFrame.volume->sunThrough(*mLight, p);
        return sunReaching(p, random);
    }

    /// The sun's light reaching p (offset off any surface) through surfaces and cloud.
    double sunReaching(const Vec3d& p, SampleRandom& random)
    {
        if (mFrame.surfaces->occluded(p, mToSun, 0.0, kInfinity)) return 0.0;
        if (!mDensity) return 1.0;
        if (mSunThroughCloud == SunThroughCloud::AsTheMarch) return mFrame.volume->sunThroughCloud(*mLight, p);
        return mMedium.transmittance(*mDensity, p, mToSun, 0.0, kInfinity, random);
    }

    const FrameToRender& mFrame;
    const RenderSettings& mSettings;
    const Medium& mMedium;
    Vec3d mToSun, mSunRadiance;
    SunThroughCloud mSunThroughCloud;
    std::optional<Medium::Density> mDensity;
    std::optional<CloudVolume::LightReaders> mLight; ///< with SunThroughCloud::AsTheMarch
};

} // namespace

RenderImage renderReference(const FrameToRender& f)
{
    // Every pixel takes every sample. Sampled adaptively, a pixel whose first
    // path found no sunlit scattering kept that one dark sample, and the
    // reference no longer converged: on the main job's displaced bank, lit
    // from behind, its single scattering came out 0.93 of the fast
    // integrator's and 0.91 of Blender Cycles'.
    RenderSettings settings = *f.settings;
    settings.image.adaptiveThreshold = 0.0;
    FrameToRender frame = f;
    frame.settings = &settings;
    const Medium medium(frame.volume, settings.medium);
    return renderCameraSamples(frame, [&] {
        return [&, tracer = PathTracer(frame, medium)](const Vec3d& cameraDir, SampleRandom& random, uint32_t) mutable {
            CameraSample seen;
            seen.radiance = tracer.radiance(frame.camera.position(), cameraDir, PathTracer::Start::Camera, random, &seen);
            return seen;
        };
    });
}

ScatteredLightGrid traceScatteredLight(const FrameToRender& f)
{
    // Three colour channels a point, 192 MiB.
    constexpr std::size_t kMaxLatticePoints = std::size_t(1) << 24;
    const CloudLighting& lighting = f.volume->lighting();
    const MultipleScattering& settings = f.settings->integrator.multipleScattering;
    const BBoxd& box = lighting.bounds();
    const Vec3d extent = box.extents();
    double spacing = settings.pathSpacing * lighting.density().voxelSize()[0];
    while (latticeSize(latticePoints(extent, spacing)) > kMaxLatticePoints) spacing *= 1.25; // coarser, within budget
    const std::array<int, 3> points = latticePoints(extent, spacing);
    ScatteredLightGrid grid;
    for (DenseGrid& channel : grid.rgb) channel = DenseGrid(box.min(), spacing, points, 0.0f, 0.0f);
    const DenseGrid& lattice = grid.rgb[0];
    if (f.settings->integrator.maxBounces <= 1) return grid; // single scattering only: nothing more to add

    // The reference's own camera paths, on a jittered grid over the part of
    // the image where the cloud's box is: each goes to its first scattering
    // in the cloud by delta tracking, where the march's samples weigh the
    // cloud (transmittance x extinction), and on from there as the
    // reference's paths go; what it carries back from its later vertices is
    // the light the march needs at that point. Finding where a ray scatters
    // costs a fraction of the path that follows: kRaysPerPath x pathsPerFrame
    // rays are cast, and at most pathsPerFrame of those that scatter, evenly
    // spread over them, go on. Their number does not depend on the image's
    // resolution: a preview's lattice is the final frame's.
    constexpr int kRaysPerPath = 4; // 80 bytes a ray: 320 MB at most (pathsPerFrame <= 1e6)
    const ImageRegion region = f.camera.regionOf(box);
    if (region.empty()) return grid;
    const std::size_t paths = std::size_t(settings.pathsPerFrame);
    const double rays = double(kRaysPerPath) * double(paths), aspect = region.width() / region.height();
    const int columns = std::max(1, int(std::lround(std::sqrt(rays * aspect))));
    const int rows = std::max(1, int(std::lround(rays / double(columns))));
    struct Gathered {
        Vec3d direction, position, light;
    };
    std::vector<std::optional<Gathered>> cast(std::size_t(columns) * std::size_t(rows));
    // The grid's cells that some of the density's leaves or tiles (with the
    // voxel around them that trilinear reads reach) cover on the image: a
    // ray through any other cell meets no cloud and is not cast. Most rays
    // over a cloud's box miss the cloud, and delta tracking walked each
    // across the whole box.
    std::vector<char> covered(cast.size(), 0);
    {
        const openvdb::FloatGrid& density = lighting.density();
        const auto cover = [&](const openvdb::CoordBBox& voxels) {
            const BBoxd world(density.indexToWorld(voxels.min().asVec3d() - Vec3d(1.0)),
                              density.indexToWorld(voxels.max().asVec3d() + Vec3d(1.0)));
            const ImageRegion seen = f.camera.regionOf(world);
            if (seen.empty()) return;
            const auto cell = [](double at, double from, double size, int cells) {
                return std::clamp(int(std::floor((at - from) / size * cells)), 0, cells - 1);
            };
            const int i0 = cell(seen.x0, region.x0, region.width(), columns),
                      i1 = cell(seen.x1, region.x0, region.width(), columns);
            const int j0 = cell(seen.y0, region.y0, region.height(), rows), j1 = cell(seen.y1, region.y0, region.height(), rows);
            for (int j = j0; j <= j1; ++j) std::fill_n(covered.begin() + std::ptrdiff_t(j) * columns + i0, i1 - i0 + 1, 1);
        };
        for (auto leaf = density.tree().cbeginLeaf(); leaf; ++leaf) cover(leaf->getNodeBoundingBox());
        auto tile = density.tree().cbeginValueOn();
        tile.setMaxDepth(openvdb::FloatTree::ValueOnCIter::LEAF_DEPTH - 1);
        for (; tile; ++tile) cover(tile.getBoundingBox());
    }
    const Medium medium(f.volume, f.settings->medium);
    // Streams apart from the camera's (frame, pixel, sample) ones.
    const uint32_t stream = uint32_t(f.frame) ^ 0x9e3779b9u;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cast.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
        Medium::Density density = medium.density();
        for (std::size_t n = r.begin(); n != r.end(); ++n) {
            if (!covered[n]) continue;
            SampleRandom random(stream, uint32_t(n), 0u);
            const double x = region.x0 + (double(n % std::size_t(columns)) + random.next()) * region.width() / columns;
            const double y = region.y0 + (double(n / std::size_t(columns)) + random.next()) * region.height() / rows;
            const Vec3d origin = f.camera.position(), dir = f.camera.direction(x, y);
            // A surface is looked for only before a collision, as the reference's paths do (nextEvent).
            const std::optional<double> scatter = medium.collision(density, origin, dir, 0.0, kInfinity, random);
            if (scatter && !f.surfaces->occluded(origin, dir, 0.0, *scatter))
                cast[n] = Gathered{dir, origin + dir * *scatter, Vec3d(0.0)};
        }
    });
    std::vector<std::size_t> scattered;
    for (std::size_t n = 0; n < cast.size(); ++n)
        if (cast[n]) scattered.push_back(n);
    std::vector<std::size_t> going(std::min(paths, scattered.size())); // every (scattered / paths)-th, in the grid's order
    for (std::size_t k = 0; k < going.size(); ++k) going[k] = scattered[k * scattered.size() / going.size()];
    std::vector<Gathered> gathered(going.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, gathered.size(), 16), [&](const tbb::blocked_range<std::size_t>& r) {
        PathTracer tracer(f, medium, PathTracer::SunThroughCloud::AsTheMarch);
        for (std::size_t k = r.begin(); k != r.end(); ++k) {
            Gathered& path = gathered[k] = *cast[going[k]];
            SampleRandom random(stream, uint32_t(going[k]), 1u);
            path.light = tracer.radiance(path.position, tracer.scatteredDirection(path.direction, random),
                                         PathTracer::Start::Scattered, random);
        }
    });

    // Each lattice point takes the mean of the paths' light weighted as a
    // trilinear read there would weigh it. The march reads the lattice where
    // camera rays scatter, as often as the paths scattered there (its samples
    // weigh the cloud as delta tracking does), so over the image its reads
    // come to the paths' mean however coarse the lattice. Points that traced
    // their own paths, interpolated, were 7% dark at 6 voxels on the main
    // job's bank, the light's rise inside the lit surface cut across. Summed
    // in the paths' order: the same lattice for any thread count. The sums
    // go into the grid, then become means.
    std::vector<float> weights(lattice.size(), 0.0f);
    for (const Gathered& path : gathered)
        lattice.forCorners(path.position, [&](std::size_t n, double weight) {
            weights[n] += float(weight);
            for (int c = 0; c < 3; ++c) grid.rgb[c][n] += float(weight * path.light[c]);
        });
    // A point no path came near takes its neighbours' mean: where the cloud
    // is thin few paths scatter, and a point left at zero darkened the reads
    // beside it. Such points are written and only the others read.
    const auto channels = [&](std::size_t n) { return Vec3d(grid.rgb[0][n], grid.rgb[1][n], grid.rgb[2][n]); };
    tbb::parallel_for(std::size_t(0), lattice.size(), [&](std::size_t n) {
        if (weights[n] > 0.0f) return;
        Vec3d sum(0.0);
        double weight = 0.0;
        const std::array<int, 3> ijk = lattice.point(n);
        for (int neighbour = 0; neighbour < 27; ++neighbour) {
            const int i = ijk[0] + neighbour % 3 - 1, j = ijk[1] + neighbour / 3 % 3 - 1, k = ijk[2] + neighbour / 9 - 1;
            if (i < 0 || j < 0 || k < 0 || i >= points[0] || j >= points[1] || k >= points[2]) continue;
            const std::size_t m = lattice.index(i, j, k);
            if (weights[m] == 0.0f) continue;
            weight += weights[m];
            sum += channels(m);
        }
        if (weight > 0.0)
            for (int c = 0; c < 3; ++c) grid.rgb[c][n] = float(sum[c] / weight);
    });
    tbb::parallel_for(std::size_t(0), lattice.size(), [&](std::size_t n) {
        if (weights[n] > 0.0f)
            for (int c = 0; c < 3; ++c) grid.rgb[c][n] /= weights[n];
    });
    return grid;
}

} // namespace vfield
