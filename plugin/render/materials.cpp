#include <vfield/render/materials.h>

#include <algorithm>
#include <cmath>

namespace vfield {

namespace {

double smoothstep(double a, double b, double x)
{
    const double t = std::clamp((x - a) / (b - a), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

Vec3d lerp(const Vec3d& a, const Vec3d& b, double t) { return a + (b - a) * t; }

} // namespace

Vec3d surfaceAlbedo(SurfaceMaterial material, const Vec3d& position, const Vec3d& normal, double low, double high)
{
    if (material == SurfaceMaterial::Painted) return Vec3d(0.62, 0.62, 0.66);
    // Grass low and flat, rock where steep, snow high and flat.
    const Vec3d grass(0.16, 0.26, 0.08), dryGrass(0.3, 0.3, 0.14), rock(0.32, 0.29, 0.26), snow(0.82, 0.84, 0.88);
    const double height = high > low ? (position[1] - low) / (high - low) : 0.0;
    Vec3d colour = lerp(grass, dryGrass, smoothstep(0.3, 0.7, height));
    colour = lerp(colour, snow, smoothstep(0.9, 0.97, height) * smoothstep(0.6, 0.85, normal[1]));
    return lerp(colour, rock, smoothstep(0.82, 0.65, normal[1]));
}

Vec3d skyRadiance(const RenderSettings& s, const Vec3d& dir)
{
    // Horizon to zenith over the lower half of the sky; haze below the horizon.
    Vec3d sky = lerp(s.sky.horizonColor, s.sky.zenithColor, smoothstep(0.0, 0.5, dir[1])) * s.sky.intensity;
    const double toSun = std::max(0.0, dir.dot(s.sun.direction.unitSafe()));
    sky += s.sun.color * (0.25 * std::pow(toSun, 64.0) + 20.0 * std::pow(toSun, 4096.0)) * s.sun.intensity;
    return sky;
}

Vec3d skyLightOnSurface(const SkySettings& sky, const Vec3d& normal)
{
    const double facingUp = 0.5 + 0.5 * normal[1];
    return lerp(sky.horizonColor, sky.zenithColor, facingUp) * (facingUp * sky.intensity);
}

} // namespace vfield
