#include <vfield/render/embree/path_tracer.h>

#include <vfield/core/trilinear_sampler.h>
#include <vfield/render/embree/camera_samples.h>

#include <openvdb/tools/Statistics.h>

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

/// The cloud as a path sees it, read through one thread's sampler.
class Medium {
public:
    /// Reads the density as the fast integrator's march does.
    using Density = TrilinearSampler<openvdb::FloatTree>;

    Medium(const CloudVolume* volume, const MediumSettings& settings) : mExtinction(settings.extinction)
    {
        if (!volume || volume->empty()) return;
        mLighting = &volume->lighting();
        const openvdb::math::MinMax<float> range = openvdb::tools::minMax(mLighting->density().tree());
        mMajorant = mExtinction * std::max(0.0f, range.max());
    }
    bool present() const { return mMajorant > 0.0; }
    Density density() const { return Density(mLighting->density().tree()); }

    /// Delta tracking along origin + t dir (dir unit), t in [tMin, tMax): the
    /// distance of the first real collision, if there is one.
    std::optional<double> collision(Density& density, const Vec3d& origin, const Vec3d& dir, double tMin, double tMax,
                                    SampleRandom& random) const
    {
        if (!present() || !mLighting->clip(origin, dir, tMin, tMax)) return std::nullopt;
        for (double t = tMin;;) {
            t -= std::log(1.0 - random.next()) / mMajorant;
            if (t >= tMax) return std::nullopt;
            if (random.next() * mMajorant < sigmaT(density, origin + dir * t)) return t;
        }
    }

    /// Ratio tracking: an unbiased estimate of the transmittance along
    /// origin + t dir, t in [tMin, tMax).
    double transmittance(Density& density, const Vec3d& origin, const Vec3d& dir, double tMin, double tMax,
                         SampleRandom& random) const
    {
        if (!present() || !mLighting->clip(origin, dir, tMin, tMax)) return 1.0;
        double transmittance = 1.0;
        for (double t = tMin;;) {
            t -= std::log(1.0 - random.next()) / mMajorant;
            if (t >= tMax) return transmittance;
            transmittance *= 1.0 - sigmaT(density, origin + dir * t) / mMajorant;
            if (transmittance < 0.1) { // Russian roulette: what survives carries the rest
                if (random.next() < 0.5) return 0.0;
                transmittance *= 2.0;
            }
        }
    }

private:
    double sigmaT(Density& density, const Vec3d& p) const
    {
        return mExtinction * std::max(0.0f, density.atIndex(mLighting->density().transform().worldToIndex(p)));
    }

    const CloudLighting* mLighting = nullptr;
    double mExtinction, mMajorant = 0.0;
};

} // namespace

RenderImage renderReference(const FrameToRender& f)
{
    const RenderSettings& s = *f.settings;
    const Vec3d toSun = s.sun.direction.unitSafe();
    const Vec3d sunRadiance = s.sun.color * s.sun.intensity;
    const Medium medium(f.volume, s.medium);
    const double albedo = s.medium.albedo;
    const int maxEvents = s.integrator.maxBounces;

    return renderCameraSamples(f, [&] {
        // A sampler per tile: it caches tree nodes and is not shared between threads.
        using Density = std::optional<Medium::Density>;
        return [&, density = medium.present() ? Density(medium.density()) : Density()](const Vec3d& cameraDir,
                                                                                       SampleRandom& random, uint32_t) mutable {
            // The sun's light reaching p (offset off any surface) through surfaces and cloud.
            const auto sunReaching = [&](const Vec3d& p) {
                if (f.surfaces->occluded(p, toSun, 0.0, kInfinity)) return 0.0;
                return medium.present() ? medium.transmittance(*density, p, toSun, 0.0, kInfinity, random) : 1.0;
            };
            CameraSample seen;
            Vec3d origin = f.camera.position(), dir = cameraDir;
            Vec3d radiance(0.0), weight(1.0);
            double firstDistance = -1.0; // of the camera ray's event; none: the sky
            for (int events = 0;;) {
                SurfaceHit hit;
                const bool isSurface = f.surfaces->intersect(origin, dir, 0.0, kInfinity, hit);
                const std::optional<double> scatter =
                    medium.present() ? medium.collision(*density, origin, dir, 0.0, isSurface ? hit.distance : kInfinity, random)
                                     : std::nullopt;
                if (events == 0) {
                    if (isSurface) seen.depth = float(hit.distance);
                    if (scatter || isSurface) firstDistance = scatter ? *scatter : hit.distance;
                }
                if (scatter) {
                    const Vec3d p = origin + dir * *scatter;
                    weight *= albedo;
                    radiance += weight * sunRadiance * (s.medium.phase(dir.dot(toSun)) * sunReaching(p));
                    if (++events >= maxEvents) break;
                    const bool backLobe = random.next() < s.medium.backWeight;
                    const double g = backLobe ? s.medium.backAnisotropy : s.medium.anisotropy;
                    const double cosTheta = sampleHenyeyGreenstein(g, random.next());
                    dir = aroundAxis(dir, cosTheta, random.next());
                    origin = p;
                } else if (isSurface) {
                    // Seen from the camera, the noise as fine as its pixel (as the fast integrator draws it).
                    const SurfaceShading surface =
                        events == 0
                            ? surfaceShading(
                                  f, hit, surfaceNoise(surfaceMaterial(f, hit.object), hit.position, pixelFootprint(f, hit, dir)))
                            : surfaceShading(f, hit);
                    const Vec3d offset = hit.position + hit.geometricNormal * 1e-3 * (1.0 + hit.distance);
                    const double cosSun = surface.normal.dot(toSun);
                    if (cosSun > 0.0) radiance += weight * surface.albedo * sunRadiance * (cosSun / M_PI * sunReaching(offset));
                    weight *= surface.albedo;
                    if (++events >= maxEvents) break;
                    // Cosine-distributed about the shading normal: the weight keeps albedo alone.
                    const double u = random.next();
                    dir = aroundAxis(surface.normal, std::sqrt(u), random.next());
                    if (dir.dot(hit.geometricNormal) <= 0.0) break; // into the surface: absorbed
                    origin = offset;
                } else {
                    // Escaped: the camera sees the sky with the sun's glow; light
                    // paths find only the dome (the sun is sampled at every event).
                    if (events > 0) radiance += weight * skyDomeRadiance(s.sky, dir);
                    else if (!s.image.transparentSky) radiance = skyRadiance(s, dir);
                    break;
                }
                if (events >= 3) { // Russian roulette on the path's weight
                    const double survive = std::clamp(std::max({weight[0], weight[1], weight[2]}), 0.05, 1.0);
                    if (random.next() >= survive) break;
                    weight /= survive;
                }
            }
            seen.radiance = firstDistance >= 0.0 ? throughHaze(s.sky, radiance, firstDistance) : radiance;
            seen.alpha = firstDistance >= 0.0 || !s.image.transparentSky ? 1.0 : 0.0;
            return seen;
        };
    });
}

} // namespace vfield
