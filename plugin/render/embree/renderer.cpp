#include <vfield/render/embree/renderer.h>

#include <vfield/core/dense_grid.h>
#include <vfield/render/embree/camera_samples.h>
#include <vfield/render/embree/path_tracer.h>
#include <vfield/render/embree/scattered_light.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

namespace vfield {

SurfaceMaterial surfaceMaterial(const FrameToRender& frame, int object)
{
    const auto material = frame.materials.find(object);
    return material != frame.materials.end() ? material->second : SurfaceMaterial{};
}

SurfaceShading surfaceShading(const FrameToRender& frame, const SurfaceHit& hit, const SurfaceNoise& noise)
{
    const SurfaceMaterial material = surfaceMaterial(frame, hit.object);
    const Vec3d normal = shadingNormal(material, hit.normal, noise);
    return {normal, surfaceAlbedo(material, hit.position, normal, frame.terrainLow, frame.terrainHigh, noise)};
}

double pixelFootprint(const FrameToRender& frame, const SurfaceHit& hit, const Vec3d& dir)
{
    // The pixel's angle at the image centre (vertical field of view over
    // rows) times the distance, widened where the ray grazes the surface.
    const double pixelAngle = 2.0 * frame.camera.tanHalfFov() / frame.settings->image.height;
    return hit.distance * pixelAngle / std::max(0.25, std::abs(hit.normal.dot(dir)));
}

Vec3d shadowRayOrigin(const SurfaceHit& hit) { return hit.position + hit.geometricNormal * 1e-3 * (1.0 + hit.distance); }

SurfaceShading surfaceShading(const FrameToRender& frame, const SurfaceHit& hit)
{
    return surfaceShading(frame, hit, surfaceNoise(surfaceMaterial(frame, hit.object), hit.position));
}

namespace {

/// Does the surface face the sun? Only then is its shadow ray traced.
bool facesSun(const FrameToRender& f, const SurfaceShading& surface)
{
    return surface.normal.dot(f.settings->sun.direction.unitSafe()) > 0.0;
}

/// The sun at a surface point: its cosine to the normal (0 where a surface
/// blocks it or the point faces away), and the share the cloud lets through.
struct SunOnSurface {
    double cosine = 0.0;
    double throughCloud = 1.0;
};

SunOnSurface sunOnSurface(const FrameToRender& f, const SurfaceHit& hit, const SurfaceShading& surface, bool sunBlocked)
{
    SunOnSurface sun;
    sun.cosine = sunBlocked ? 0.0 : std::max(0.0, surface.normal.dot(f.settings->sun.direction.unitSafe()));
    if (sun.cosine > 0 && f.volume) sun.throughCloud = f.volume->surfaceSunTransmittance(shadowRayOrigin(hit));
    return sun;
}

/// The light a surface point sends back as the fast integrator sees it: the
/// sun (softened through the cloud) and the sky.
Vec3d directlyLitSurface(const FrameToRender& f, const SurfaceShading& surface, const SunOnSurface& sun)
{
    const RenderSettings& s = *f.settings;
    const Vec3d sunRadiance = s.sun.color * s.sun.intensity;
    const Vec3d light = sunRadiance * (sun.cosine * sun.throughCloud / M_PI) + skyLightOnSurface(s.sky, surface.normal);
    return surface.albedo * light;
}

/// The mean radiance the surfaces under the cloud send up into it (lit by the
/// sun, through the cloud, and by the sky), from rays cast straight down over
/// its box, 8 to 16 across its wider side; the sky's horizon where there is
/// no ground. The fast integrator's bounce light: the reference finds cloud
/// bases lit by the ground as brightly as by the sky. The rays stand on a
/// lattice anchored at the world's origin, its spacing a power of two, so a
/// box that grows a little keeps the rays it had and its light barely moves.
Vec3d groundRadianceBelow(const FrameToRender& f)
{
    const RenderSettings& s = *f.settings;
    if (!f.volume || f.volume->empty()) return Vec3d(0.0);
    const BBoxd& box = f.volume->lighting().bounds();
    constexpr int kRaysAcross = 16;
    const double spacing = std::exp2(std::ceil(std::log2(std::max(box.extents()[0], box.extents()[2]) / kRaysAcross)));
    const auto raysAlong = [&](int axis) {
        const int from = int(anchoredIndexBelow(box.min(), spacing)[axis]);
        return std::make_pair(from, std::max(from + 1, int(std::ceil(box.max()[axis] / spacing))));
    };
    const auto [iFrom, iTo] = raysAlong(0);
    const auto [kFrom, kTo] = raysAlong(2);
    Vec3d sum(0.0);
    for (int i = iFrom; i < iTo; ++i)
        for (int k = kFrom; k < kTo; ++k) {
            const Vec3d from((i + 0.5) * spacing, box.max()[1], (k + 0.5) * spacing);
            SurfaceHit hit;
            const bool ground = f.surfaces->intersect(from, Vec3d(0, -1, 0), 0.0, std::numeric_limits<double>::max(), hit);
            if (!ground) {
                sum += s.sky.horizonColor * s.sky.intensity;
                continue;
            }
            const SurfaceShading surface = surfaceShading(f, hit);
            const bool sunBlocked = facesSun(f, surface) && f.surfaces->occluded(shadowRayOrigin(hit), s.sun.direction.unitSafe(),
                                                                                 0.0, std::numeric_limits<double>::max());
            sum += directlyLitSurface(f, surface, sunOnSurface(f, hit, surface, sunBlocked));
        }
    return sum / double((iTo - iFrom) * (kTo - kFrom));
}

/// The fast integrator's lattice of paths: from the paths the frame was
/// given (its own and its neighbours'), or else from its own, traced here.
ScatteredLightGrid scatteredLightOf(const FrameToRender& f)
{
    if (!f.scatteredPaths.empty()) return gatherScatteredLight(f, f.scatteredPaths);
    const ScatteredPaths own = traceScatteredPaths(f);
    return gatherScatteredLight(f, {&own});
}

/// IntegratorKind::Fast: surfaces lit directly by the sun and the sky; the
/// cloud ray-marched in front of them (CloudVolume), its light scattered
/// more than once by octaves or from the frame's lattice of paths
/// (scatteredLightOf). A surface's noise is drawn once per pixel (at its
/// first sample on that surface, in each of adaptive sampling's passes); its
/// geometry, light and shadows at every sample. Camera rays, and then their shadow rays, are traced a packet at
/// a time.
RenderImage renderFast(const FrameToRender& f)
{
    const RenderSettings& s = *f.settings;
    const Vec3d sunRadiance = s.sun.color * s.sun.intensity, toSun = s.sun.direction.unitSafe();
    const Vec3d skyAmbient = cloudAmbientRadiance(s.sky, groundRadianceBelow(f));
    const bool tracedLight =
        f.volume && !f.volume->empty() && s.integrator.multipleScattering.method == MultipleScatteringMethod::Paths;
    const ScatteredLightGrid scattered = tracedLight ? scatteredLightOf(f) : ScatteredLightGrid();
    constexpr int kLanes = SamplePacket::kSize;
    constexpr double kFar = std::numeric_limits<double>::max();

    return renderCameraPackets(f, [&] {
        struct PixelNoise {
            uint32_t pixel = std::numeric_limits<uint32_t>::max();
            int object = -1;
            SurfaceNoise noise;
        };
        return [&, drawn = std::array<PixelNoise, kLanes>()](SamplePacket& packet, CameraSample* seen) mutable {
            const int count = packet.count;
            std::array<Vec3d, kLanes> shadowOrigins, towardsSun;
            std::array<SurfaceHit, kLanes> hits;
            std::array<SurfaceShading, kLanes> surfaces;
            std::array<bool, kLanes> isSurface{}, litSide{}, sunBlocked{};
            towardsSun.fill(toSun);
            f.surfaces->intersect(packet.origins.data(), packet.dirs.data(), count, 0.0, kFar, hits.data(), isSurface.data(),
                                  packet.times.data());
            for (int lane = 0; lane < count; ++lane) {
                if (!isSurface[lane]) continue;
                const SurfaceHit& hit = hits[lane];
                PixelNoise& noise = drawn[lane];
                if (noise.pixel != packet.pixels[lane] || noise.object != hit.object)
                    noise = {
                        packet.pixels[lane], hit.object,
                        surfaceNoise(surfaceMaterial(f, hit.object), hit.position, pixelFootprint(f, hit, packet.dirs[lane]))};
                surfaces[lane] = surfaceShading(f, hit, noise.noise);
                litSide[lane] = facesSun(f, surfaces[lane]);
                shadowOrigins[lane] = shadowRayOrigin(hit);
            }
            f.surfaces->occluded(shadowOrigins.data(), towardsSun.data(), litSide.data(), count, 0.0, kFar, sunBlocked.data(),
                                 packet.times.data());

            for (int lane = 0; lane < count; ++lane) {
                const Vec3d& dir = packet.dirs[lane];
                const SurfaceHit& hit = hits[lane];
                CameraSample& sample = seen[lane] = CameraSample();
                if (isSurface[lane]) {
                    const SunOnSurface sun = sunOnSurface(f, hit, surfaces[lane], sunBlocked[lane]);
                    sample.behind = throughHaze(s.sky, directlyLitSurface(f, surfaces[lane], sun), hit.distance);
                    sample.behindAlpha = 1.0;
                    sample.depth = float(hit.distance);
                    sample.object = hit.object;
                    sample.objectPosition = hit.objectPosition;
                    sample.normal = surfaces[lane].normal;
                    sample.shadow = sun.cosine > 0.0 ? 1.0 - sun.throughCloud : 0.0;
                } else if (!s.image.transparentSky) {
                    // Premultiplied: a drawn sky is an opaque background; a
                    // transparent one adds neither light nor coverage.
                    sample.behind = skyRadiance(s, dir);
                    sample.behindAlpha = 1.0;
                }
                if (f.volume) {
                    std::optional<CloudMotion::Instant> motion;
                    if (f.motion) motion.emplace(*f.motion, packet.seconds[lane]);
                    const CloudVolume::Segment cloud = f.volume->march(
                        packet.origins[lane], dir, 0.0, isSurface[lane] ? hit.distance : 1e30, packet.randoms[lane].next(),
                        sunRadiance, skyAmbient, tracedLight ? &scattered : nullptr, motion ? &*motion : nullptr);
                    sample.cloud = throughHaze(s.sky, cloud.radiance, cloud.distance, 1.0 - cloud.transmittance);
                    sample.transmittance = cloud.transmittance;
                }
            }
        };
    });
}

} // namespace

RenderImage renderFrame(const FrameToRender& frame)
{
    return frame.settings->integrator.kind == IntegratorKind::Reference ? renderReference(frame) : renderFast(frame);
}

} // namespace vfield
