#include <vfield/render/materials.h>

#include <vfield/core/noise.h>

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

/// The noise every terrain shares: the same rock streaks in every frame and back-end.
const GradientNoise& terrainNoise()
{
    static const GradientNoise noise(20171);
    return noise;
}

/// The bump noise's frequency (1 / world units).
constexpr double kBumpFrequency = 1.0 / 2.5;

/// The period of the coarsest detail octave (world units): the next below
/// the fine colour noise's finest, 0.75.
constexpr double kDetailPeriod = 0.375;
constexpr int kMaxDetailOctaves = 6;

} // namespace

SurfaceNoise surfaceNoise(const SurfaceMaterial& material, const Vec3d& position, double pixelFootprint)
{
    SurfaceNoise noise;
    if (material.kind == SurfaceMaterial::Kind::Painted) return noise;
    noise.bumpGradient =
        Vec3d(fbmSample(terrainNoise(), Vec3f(position * kBumpFrequency), FractalOptions{2, 2.0, 0.5}).gradient) * kBumpFrequency;
    // Broad and fine colour, and stone's streaks (stretched along y), in one batch.
    const FbmQuery colours[] = {{Vec3f(position * (1.0 / 40.0)), {3, 2.0, 0.5}},
                                {Vec3f(position * (1.0 / 3.0)), {3, 2.0, 0.5}},
                                {Vec3f((position + Vec3d(0, 3.1 * position[1], 0)) * (1.0 / 6.0)), {2, 2.0, 0.5}}};
    float values[3];
    fbm(terrainNoise(), colours, 3, values);
    noise.broad = values[0];
    noise.fine = values[1];
    noise.stone = values[2];
    // Detail octaves while a pixel holds two samples of their period, each
    // fading in over the octave above that limit so nothing pops as the
    // camera moves. Colour amplitudes halve per octave; each octave tilts the
    // normal alike (heights halve as the period does, so slopes stay): rock
    // grain at every scale the pixels resolve.
    double period = kDetailPeriod, amplitude = 0.5;
    for (int octave = 0; octave < kMaxDetailOctaves && period > 2.0 * pixelFootprint; ++octave) {
        const double fade = std::min(1.0, period / (2.0 * pixelFootprint) - 1.0);
        // Shifted per octave so the octaves do not line up at the origin.
        const NoiseSample s = terrainNoise().sample(Vec3f(position / period + Vec3d(17.1 * (octave + 1))));
        noise.detail += amplitude * fade * double(s.value);
        noise.bumpGradient += Vec3d(s.gradient) * (0.5 * fade);
        period *= 0.5;
        amplitude *= 0.5;
    }
    return noise;
}

Vec3d surfaceAlbedo(const SurfaceMaterial& material, const Vec3d& position, const Vec3d& normal, double low, double high,
                    const SurfaceNoise& noise)
{
    if (material.kind == SurfaceMaterial::Kind::Painted) return material.paint;
    // Grass low and flat, rock where steep, snow high and flat; the borders
    // between them wander with the noise, as do the colours within each.
    const Vec3d grass(0.11, 0.2, 0.05), dryGrass(0.26, 0.24, 0.11), rock(0.24, 0.2, 0.16), darkRock(0.1, 0.09, 0.08),
        snow(0.85, 0.87, 0.9);
    const double broad = noise.broad, fine = noise.fine;
    const double height = (high > low ? (position[1] - low) / (high - low) : 0.0) + 0.08 * broad;
    const double slope = normal[1] + 0.12 * fine;
    Vec3d colour = lerp(grass, dryGrass, smoothstep(0.25, 0.75, height + 0.25 * broad));
    colour *= 0.8 + 0.4 * (0.5 + 0.5 * fine);
    const Vec3d stone = lerp(darkRock, rock, 0.5 + 0.5 * noise.stone);
    colour = lerp(colour, stone, smoothstep(0.72, 0.55, slope)) * (1.0 + 0.4 * noise.detail);
    return lerp(colour, snow, smoothstep(0.85, 0.95, height) * smoothstep(0.5, 0.75, slope));
}

Vec3d shadingNormal(const SurfaceMaterial& material, const Vec3d& normal, const SurfaceNoise& noise)
{
    if (material.kind == SurfaceMaterial::Kind::Painted) return normal;
    // Bumps a few units across: the noise's gradient tilts the normal, its
    // part along the normal removed.
    constexpr double kStrength = 0.6;
    const Vec3d gradient = noise.bumpGradient - normal * noise.bumpGradient.dot(normal);
    return (normal - gradient * (kStrength / kBumpFrequency * 0.1)).unitSafe();
}

Vec3d skyDomeRadiance(const SkySettings& sky, const Vec3d& dir)
{
    // Horizon to zenith over the lower half of the sky; haze below the horizon.
    return lerp(sky.horizonColor, sky.zenithColor, smoothstep(0.0, 0.5, dir[1])) * sky.intensity;
}

Vec3d skyRadiance(const RenderSettings& s, const Vec3d& dir)
{
    Vec3d sky = skyDomeRadiance(s.sky, dir);
    // The sun's glow and disk, cos^64 and cos^4096, by squaring (pow costs
    // more than the rest of the sky); where the glow is under a tenth, the disk
    // is under 1e-64.
    double glow = std::max(0.0, dir.dot(s.sun.direction.unitSafe()));
    for (int i = 0; i < 6; ++i) glow *= glow;
    double disk = 0.0;
    if (glow > 1e-1) {
        disk = glow;
        for (int i = 0; i < 6; ++i) disk *= disk;
    }
    sky += s.sun.color * (0.25 * glow + 20.0 * disk) * s.sun.intensity;
    return sky;
}

Vec3d cloudAmbientRadiance(const SkySettings& sky, const Vec3d& below)
{
    // Over the upper hemisphere (uniform in y) smoothstep(0, 0.5, y) averages 3/4.
    const Vec3d upper = lerp(sky.horizonColor, sky.zenithColor, 0.75) * sky.intensity;
    return (upper + below) * 0.5;
}

Vec3d throughHaze(const SkySettings& sky, const Vec3d& radiance, double distance, double coverage)
{
    if (sky.hazeDistance <= 0.0) return radiance;
    const double kept = std::exp(-distance / sky.hazeDistance);
    return radiance * kept + sky.horizonColor * (sky.intensity * (1.0 - kept) * coverage);
}

Vec3d skyLightOnSurface(const SkySettings& sky, const Vec3d& normal)
{
    const double facingUp = 0.5 + 0.5 * normal[1];
    return lerp(sky.horizonColor, sky.zenithColor, facingUp) * (facingUp * sky.intensity);
}

SurfaceMaterial surfaceMaterialOf(const ObjectSettings& object)
{
    const bool isGround = object.mesh.kind == MeshSettings::Kind::Terrain || object.mesh.kind == MeshSettings::Kind::Heightmap;
    return isGround ? SurfaceMaterial::terrain() : SurfaceMaterial::painted(object.color);
}

} // namespace vfield
