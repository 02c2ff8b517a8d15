#pragma once
/// @file paths.h
/// Within libvfield's Embree renderer: the reference's paths through a frame
/// (PathTracer), over the cloud as they see it (Medium: delta and ratio
/// tracking under a grid of majorants), shared by the reference integrator
/// (path_tracer.cpp) and the fast one's light gathered from its paths
/// (scattered_light.cpp).

#include <vfield/core/dense_grid.h>
#include <vfield/core/trilinear_sampler.h>
#include <vfield/render/embree/camera_samples.h>
#include <vfield/render/embree/renderer.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace vfield {

inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// A unit vector at angle acos(cosTheta) from unit axis, turned by 2 pi u about it.
inline Vec3d aroundAxis(const Vec3d& axis, double cosTheta, double u)
{
    const Vec3d helper = std::abs(axis[0]) < 0.9 ? Vec3d(1, 0, 0) : Vec3d(0, 1, 0);
    const Vec3d tangent = axis.cross(helper).unitSafe(), bitangent = axis.cross(tangent);
    const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta)), phi = 2.0 * M_PI * u;
    return (tangent * (sinTheta * std::cos(phi)) + bitangent * (sinTheta * std::sin(phi)) + axis * cosTheta).unitSafe();
}

/// The cosine between the directions of propagation before and after
/// scattering, drawn from Henyey-Greenstein with eccentricity g.
inline double sampleHenyeyGreenstein(double g, double u)
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

    /// reach: how far a CloudMotion displaces reads (0 without one); each
    /// value then bounds the cells that far around it too.
    /// The cells lie on a lattice anchored at the world's origin, not at the
    /// box: a cloud that grows in one place keeps the cells, and so the free
    /// paths, it had everywhere else.
    MajorantGrid(const openvdb::FloatGrid& density, const BBoxd& box, double extinction, double reach)
    {
        const double voxel = density.voxelSize()[0];
        for (mCell = kMajorantVoxels * voxel;; mCell *= 2.0) {
            mFirstCell = anchoredIndexBelow(box.min(), mCell);
            for (int axis = 0; axis < 3; ++axis) {
                mOrigin[axis] = double(mFirstCell[axis]) * mCell;
                mCells[axis] = std::max(1, int(std::ceil((box.max()[axis] - mOrigin[axis]) / mCell)));
            }
            if (latticeSize(mCells) <= kMaxMajorantCells) break;
        }
        mMajorant.assign(latticeSize(mCells), 0.0f);
        // A value (a voxel, or a tile's voxels) reaches reads within a voxel of it.
        for (auto value = density.cbeginValueOn(); value; ++value) {
            if (*value <= 0.0f) continue;
            const openvdb::CoordBBox voxels = value.getBoundingBox();
            const Vec3d lo = density.indexToWorld(voxels.min()) - Vec3d(voxel + reach),
                        hi = density.indexToWorld(voxels.max()) + Vec3d(voxel + reach);
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

    /// Calls segment(from, to, majorant, cell) for the cells that origin + t
    /// dir (dir unit) crosses for t in [tMin, tMax) (within the box), in
    /// order, skipping cells with nothing in them, while it returns true;
    /// cell is the cell's key, the same for any box that holds it. The first
    /// segment starts where the ray enters its cell, though no earlier than
    /// rayStart (<= tMin), and may so start before tMin: points drawn from a
    /// cell's face stay where they were when the box, and with it tMin,
    /// moves. Points before tMin are the caller's to discard.
    template<typename Segment>
    void walk(const Vec3d& origin, const Vec3d& dir, double rayStart, double tMin, double tMax, const Segment& segment) const
    {
        std::array<int, 3> cell, step;
        std::array<double, 3> next, delta;
        const Vec3d start = (origin + dir * tMin - mOrigin) / mCell;
        double cellEntry = rayStart;
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
            cellEntry = std::max(cellEntry, next[axis] - delta[axis]);
        }
        for (double t = std::min(cellEntry, tMin); t < tMax;) {
            const int axis = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
            const double exit = std::min(next[axis], tMax);
            const float majorant = mMajorant[index(cell[0], cell[1], cell[2])];
            if (majorant > 0.0f && exit > t && !segment(t, exit, double(majorant), key(cell))) return;
            t = exit;
            cell[axis] += step[axis];
            if (cell[axis] < 0 || cell[axis] >= mCells[axis]) return;
            next[axis] += delta[axis];
        }
    }

private:
    uint64_t key(const std::array<int, 3>& cell) const
    {
        constexpr uint64_t kBits = 21, kMask = (uint64_t(1) << kBits) - 1;
        uint64_t key = 0;
        for (int axis = 0; axis < 3; ++axis) key |= (uint64_t(mFirstCell[axis] + cell[axis]) & kMask) << (kBits * axis);
        return key;
    }
    std::size_t index(int i, int j, int k) const
    {
        return (std::size_t(k) * std::size_t(mCells[1]) + std::size_t(j)) * std::size_t(mCells[0]) + std::size_t(i);
    }

    Vec3d mOrigin;
    std::array<int64_t, 3> mFirstCell{0, 0, 0}; ///< mOrigin / mCell
    double mCell = 1.0;
    std::array<int, 3> mCells{1, 1, 1};
    std::vector<float> mMajorant; ///< extinction, 1 / world units
};

/// The cloud as paths see it: sigma_t = extinction x the density read
/// trilinearly, free paths drawn under the majorant grid's bounds. With a
/// CloudMotion, the density is read where the motion brought it from.
class Medium {
public:
    /// Reads the density as the fast integrator's march does.
    using Density = TrilinearSampler<openvdb::FloatTree>;

    Medium(const CloudVolume* volume, const MediumSettings& settings, const CloudMotion* motion)
        : mExtinction(settings.extinction), mReach(motion ? motion->reach() : 0.0)
    {
        if (!volume || volume->empty() || mExtinction <= 0.0) return;
        mLighting = &volume->lighting();
        BBoxd box = mLighting->bounds();
        box.expand(mReach);
        mMajorants.emplace(mLighting->density(), box, mExtinction, mReach);
    }
    bool present() const { return mMajorants.has_value(); }
    Density density() const { return Density(mLighting->density().tree()); }

    /// Delta tracking along origin + t dir (dir unit), t in [tMin, tMax): the
    /// distance of the first real collision, if there is one.
    std::optional<double> collision(Density& density, CloudMotion::Instant* motion, const Vec3d& origin, const Vec3d& dir,
                                    double tMin, double tMax, SampleRandom& random) const
    {
        std::optional<double> hit;
        const double rayStart = tMin;
        if (!present() || !mLighting->clip(origin, dir, tMin, tMax, mReach)) return hit;
        // Each cell's points come from a stream of the cell's own: a cell
        // that the ray crosses in one frame's box and not in the next one's
        // does not move the points drawn in the cells after it.
        const SampleRandom::Split cells = random.split();
        mMajorants->walk(origin, dir, rayStart, tMin, tMax, [&](double from, double to, double majorant, uint64_t cell) {
            SampleRandom inCell = cells(cell);
            for (double t = from;;) {
                t -= std::log(1.0 - inCell.next()) / majorant;
                if (t >= to) return true;
                // Drawn for every point, so that the draws after tMin do not depend on it.
                const double accept = inCell.next();
                if (t >= tMin && accept * majorant < sigmaT(density, motion, origin + dir * t)) {
                    hit = t;
                    return false;
                }
            }
        });
        return hit;
    }

    /// Ratio tracking: an unbiased estimate of the transmittance along
    /// origin + t dir, t in [tMin, tMax).
    double transmittance(Density& density, CloudMotion::Instant* motion, const Vec3d& origin, const Vec3d& dir, double tMin,
                         double tMax, SampleRandom& random) const
    {
        double transmittance = 1.0;
        const double rayStart = tMin;
        if (!present() || !mLighting->clip(origin, dir, tMin, tMax, mReach)) return transmittance;
        const SampleRandom::Split cells = random.split(); // as in collision
        mMajorants->walk(origin, dir, rayStart, tMin, tMax, [&](double from, double to, double majorant, uint64_t cell) {
            SampleRandom inCell = cells(cell);
            for (double t = from;;) {
                t -= std::log(1.0 - inCell.next()) / majorant;
                if (t >= to) return true;
                if (t < tMin) continue;
                transmittance *= 1.0 - sigmaT(density, motion, origin + dir * t) / majorant;
                if (transmittance < 0.1) { // Russian roulette: what survives carries the rest
                    if (inCell.next() < 0.5) {
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
    double sigmaT(Density& density, CloudMotion::Instant* motion, const Vec3d& p) const
    {
        const Vec3d source = motion ? motion->source(p) : p;
        return mExtinction * std::max(0.0f, density.atIndex(mLighting->density().transform().worldToIndex(source)));
    }

    const CloudLighting* mLighting = nullptr;
    double mExtinction, mReach;
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

    /// The instant the next paths see: surfaces at the shutter's time (in
    /// [0, 1]), the cloud `seconds` from the frame's instant (FrameToRender::motion).
    void setInstant(float time, double seconds)
    {
        mTime = time;
        if (mFrame.motion) mMotion.emplace(*mFrame.motion, seconds);
    }

    /// Where a path leaves its first vertex: the camera, or a point where it
    /// has just scattered in the cloud.
    enum class Start { Camera, Scattered };

    /// The radiance carried back along the path that leaves `origin` along
    /// `dir` (unit). From the camera, `seen` receives what the camera sees
    /// (the sky's glow, haze), as the cloud's light where the path first
    /// scatters in the cloud and as what lies behind it otherwise, and the
    /// first surface's depth, object, normal and cloud shadow; from a
    /// scattering point, the result is the light of the path's later vertices
    /// alone, weight 1 after that scattering.
    Vec3d radiance(Vec3d origin, Vec3d dir, Start start, SampleRandom& random, CameraSample* seen = nullptr)
    {
        const RenderSettings& s = mSettings;
        const bool fromCamera = start == Start::Camera;
        Vec3d radiance(0.0), weight(1.0);
        double firstDistance = -1.0;  // of the camera ray's event; none: the sky
        bool inCloud = false;         // the camera ray's event is a scattering
        SurfaceShading cameraSurface; // of the camera ray's surface, in front or behind its event
        for (int events = fromCamera ? 0 : 1;;) {
            const bool cameraRay = fromCamera && events == 0;
            SurfaceHit hit;
            bool isSurface = false;
            const std::optional<double> scatter = nextEvent(origin, dir, cameraRay, random, hit, isSurface);
            if (cameraRay) {
                if (scatter || isSurface) firstDistance = scatter ? *scatter : hit.distance;
                inCloud = scatter.has_value();
                if (isSurface) {
                    // Seen from the camera, the noise as fine as its pixel (as the fast integrator draws it).
                    cameraSurface = surfaceShading(
                        mFrame, hit,
                        surfaceNoise(surfaceMaterial(mFrame, hit.object), hit.position, pixelFootprint(mFrame, hit, dir)));
                    if (seen) seeSurface(hit, cameraSurface, *seen);
                }
            }
            if (scatter) {
                const Vec3d p = origin + dir * *scatter;
                weight *= s.medium.albedo;
                radiance += weight * mSunRadiance * (s.medium.phase(dir.dot(mToSun)) * sunAtScattering(p, random));
                if (++events >= s.integrator.maxBounces) break;
                dir = scatteredDirection(dir, random);
                origin = p;
            } else if (isSurface) {
                const SurfaceShading surface = cameraRay ? cameraSurface : surfaceShading(mFrame, hit);
                const Vec3d offset = shadowRayOrigin(hit);
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
        const Vec3d seenRadiance = firstDistance >= 0.0 ? throughHaze(s.sky, radiance, firstDistance) : radiance;
        if (seen && inCloud) {
            seen->cloud = seenRadiance;
            seen->transmittance = 0.0;
        } else if (seen) {
            seen->behind = seenRadiance;
            seen->behindAlpha = firstDistance >= 0.0 || !s.image.transparentSky ? 1.0 : 0.0;
        }
        return seenRadiance;
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
    /// What the passes keep of the surface a camera ray meets, in front of
    /// its event or behind it: its depth, object and normal, and the share of
    /// the sun's light the cloud takes from it, as the fast integrator
    /// estimates it (where no surface shadows it).
    void seeSurface(const SurfaceHit& hit, const SurfaceShading& surface, CameraSample& seen) const
    {
        seen.depth = float(hit.distance);
        seen.object = hit.object;
        seen.objectPosition = hit.objectPosition;
        seen.normal = surface.normal;
        const Vec3d offset = shadowRayOrigin(hit);
        // Its own shadow ray: only when the passes are asked for.
        if (mFrame.passes && surface.normal.dot(mToSun) > 0.0 && mFrame.volume &&
            !mFrame.surfaces->occluded(offset, mToSun, 0.0, kInfinity, mTime))
            seen.shadow = 1.0 - mFrame.volume->surfaceSunTransmittance(offset);
    }

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
            isSurface = mFrame.surfaces->intersect(origin, dir, 0.0, kInfinity, hit, mTime);
            if (!mDensity) return std::nullopt;
            return mMedium.collision(*mDensity, motion(), origin, dir, 0.0, isSurface ? hit.distance : kInfinity, random);
        }
        const std::optional<double> scatter = mMedium.collision(*mDensity, motion(), origin, dir, 0.0, kInfinity, random);
        if (scatter && !mFrame.surfaces->occluded(origin, dir, 0.0, *scatter, mTime)) return scatter;
        isSurface = mFrame.surfaces->intersect(origin, dir, 0.0, kInfinity, hit, mTime);
        return scatter && !(isSurface && hit.distance < *scatter) ? scatter : std::nullopt;
    }

    /// The sun's light reaching p, a scattering point in the cloud. Taken as
    /// the march takes it, surfaces' shadows come from CloudLighting's grid
    /// instead of a ray to the sun at every event.
    double sunAtScattering(const Vec3d& p, SampleRandom& random)
    {
        if (mSunThroughCloud == SunThroughCloud::AsTheMarch) return mFrame.volume->sunThrough(*mLight, source(p));
        return sunReaching(p, random);
    }

    /// The sun's light reaching p (offset off any surface) through surfaces and cloud.
    double sunReaching(const Vec3d& p, SampleRandom& random)
    {
        if (mFrame.surfaces->occluded(p, mToSun, 0.0, kInfinity, mTime)) return 0.0;
        if (!mDensity) return 1.0;
        if (mSunThroughCloud == SunThroughCloud::AsTheMarch) return mFrame.volume->sunThroughCloud(*mLight, source(p));
        return mMedium.transmittance(*mDensity, motion(), p, mToSun, 0.0, kInfinity, random);
    }

    CloudMotion::Instant* motion() { return mMotion ? &*mMotion : nullptr; }
    /// Where the frame's cloud holds what lies at p at this instant.
    Vec3d source(const Vec3d& p) { return mMotion ? mMotion->source(p) : p; }

    const FrameToRender& mFrame;
    const RenderSettings& mSettings;
    const Medium& mMedium;
    Vec3d mToSun, mSunRadiance;
    SunThroughCloud mSunThroughCloud;
    std::optional<Medium::Density> mDensity;
    std::optional<CloudVolume::LightReaders> mLight; ///< with SunThroughCloud::AsTheMarch
    float mTime = 0.0f;                              ///< setInstant's
    std::optional<CloudMotion::Instant> mMotion;     ///< setInstant's, with FrameToRender::motion
};

} // namespace vfield
