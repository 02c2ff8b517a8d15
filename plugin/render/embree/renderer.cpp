#include <vfield/render/embree/renderer.h>

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace vfield {

namespace {

/// A counter-based random stream: each (frame, pixel, sample) has its own,
/// whatever thread draws it (PCG-style hashing of the counter).
class SampleRandom {
public:
    SampleRandom(uint32_t frame, uint32_t pixel, uint32_t sample)
        : mState(hash(hash(hash(frame) ^ pixel) ^ (uint64_t(sample) << 32)))
    {}
    double next() { return double(hash(mState++) >> 11) * (1.0 / 9007199254740992.0); }

private:
    static uint64_t hash(uint64_t x)
    {
        x ^= x >> 33;
        x *= 0xff51afd7ed558ccdull;
        x ^= x >> 33;
        x *= 0xc4ceb9fe1a85ec53ull;
        x ^= x >> 33;
        return x;
    }
    uint64_t mState;
};

} // namespace

RenderImage renderFrame(const FrameToRender& f)
{
    const RenderSettings& s = *f.settings;
    const Vec3d toSun = s.sun.direction.unitSafe();
    const Vec3d sunRadiance = s.sun.color * s.sun.intensity;
    // What the sky gives a cloud from all around: its mean radiance.
    const Vec3d skyAmbient = (s.sky.zenithColor + s.sky.horizonColor) * (0.5 * s.sky.intensity);

    const int width = s.image.width, height = s.image.height, samplesPerPixel = s.image.samplesPerPixel;
    RenderImage image;
    image.width = width;
    image.height = height;
    image.rgba.assign(std::size_t(width) * height * 4, 0.0f);
    image.depth.assign(std::size_t(width) * height, std::numeric_limits<float>::infinity());

    const auto shadeSurface = [&](const SurfaceHit& hit) {
        const auto material = f.materials.find(hit.object);
        const bool isTerrain = material != f.materials.end() && material->second == SurfaceMaterial::Terrain;
        const Vec3d albedo = surfaceAlbedo(isTerrain ? SurfaceMaterial::Terrain : SurfaceMaterial::Painted, hit.position,
                                           hit.normal, f.terrainLow, f.terrainHigh);
        const Vec3d offset = hit.position + hit.geometricNormal * 1e-3 * (1.0 + hit.distance);
        double sun = std::max(0.0, hit.normal.dot(toSun));
        if (sun > 0 && f.surfaces->occluded(offset, toSun, 0.0, std::numeric_limits<double>::max())) sun = 0.0;
        if (sun > 0 && f.volume) sun *= f.volume->lighting().sunTransmittance(offset);
        const Vec3d light = sunRadiance * (sun / M_PI) + skyLightOnSurface(s.sky, hit.normal);
        return Vec3d(albedo[0] * light[0], albedo[1] * light[1], albedo[2] * light[2]);
    };

    const int tile = 16;
    tbb::parallel_for(tbb::blocked_range2d<int>(0, height, tile, 0, width, tile), [&](const tbb::blocked_range2d<int>& r) {
        for (int y = r.rows().begin(); y != r.rows().end(); ++y)
            for (int x = r.cols().begin(); x != r.cols().end(); ++x) {
                const uint32_t pixel = uint32_t(y) * uint32_t(width) + uint32_t(x);
                Vec3d colour(0.0);
                double alpha = 0.0;
                float depth = std::numeric_limits<float>::infinity();
                for (int sample = 0; sample < samplesPerPixel; ++sample) {
                    SampleRandom random(uint32_t(f.frame), pixel, uint32_t(sample));
                    // One sample at the pixel centre, the rest jittered over it.
                    const double jx = samplesPerPixel == 1 ? 0.5 : random.next();
                    const double jy = samplesPerPixel == 1 ? 0.5 : random.next();
                    const Vec3d dir = f.camera.direction(x + jx, y + jy);
                    SurfaceHit hit;
                    const bool isSurface =
                        f.surfaces->intersect(f.camera.position(), dir, 0.0, std::numeric_limits<double>::max(), hit);
                    // Premultiplied: a drawn sky is an opaque background; a
                    // transparent one adds neither light nor coverage.
                    const bool drawSky = !s.image.transparentSky;
                    Vec3d radiance = isSurface ? shadeSurface(hit) : drawSky ? skyRadiance(s, dir) : Vec3d(0.0);
                    double opacity = isSurface || drawSky ? 1.0 : 0.0;
                    if (f.volume) {
                        const CloudVolume::Segment cloud =
                            f.volume->march(f.camera.position(), dir, 0.0, isSurface ? hit.distance : 1e30, random.next(),
                                            sunRadiance, skyAmbient);
                        radiance = cloud.radiance + radiance * cloud.transmittance;
                        opacity = 1.0 - (1.0 - opacity) * cloud.transmittance;
                    }
                    colour += radiance;
                    alpha += opacity;
                    if (isSurface) depth = std::min(depth, float(hit.distance));
                }
                const double n = samplesPerPixel;
                float* out = &image.rgba[4 * std::size_t(pixel)];
                out[0] = float(colour[0] / n);
                out[1] = float(colour[1] / n);
                out[2] = float(colour[2] / n);
                out[3] = float(alpha / n);
                image.depth[pixel] = depth;
            }
    });
    return image;
}

} // namespace vfield
