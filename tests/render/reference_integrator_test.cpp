// The reference path tracer against exact results, and the fast integrator
// measured against it on small feature scenes.

#include "test_meshes.h"

#include <vfield/core/noise.h>
#include <vfield/mesh/procedural.h>
#include <vfield/render/embree/renderer.h>

#include <catch2/catch.hpp>

#include <openvdb/tools/Interpolation.h>

#include <tbb/global_control.h>

#include <cmath>
#include <functional>
#include <limits>

using namespace vfield;

namespace {

/// A density grid over [-r, r]^3 around centre, density(p) at voxel centres, zero where it gives <= 0.
openvdb::FloatGrid::Ptr densityGrid(const Vec3d& centre, double r, double voxel,
                                    const std::function<float(const Vec3d&)>& density)
{
    openvdb::initialize();
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
    openvdb::FloatGrid::Accessor acc = grid->getAccessor();
    const int n = int(std::ceil(r / voxel));
    const openvdb::Coord c = openvdb::Coord::round(centre / voxel);
    for (int i = -n; i <= n; ++i)
        for (int j = -n; j <= n; ++j)
            for (int k = -n; k <= n; ++k) {
                const openvdb::Coord ijk = c.offsetBy(i, j, k);
                const float value = density(grid->indexToWorld(ijk));
                if (value > 0.0f) acc.setValue(ijk, value);
            }
    return grid;
}

/// Where origin + t dir (dir unit) crosses the sphere: the length inside it.
double chordThroughSphere(const Vec3d& origin, const Vec3d& dir, const Vec3d& centre, double radius)
{
    const Vec3d oc = origin - centre;
    const double b = oc.dot(dir), disc = b * b - (oc.dot(oc) - radius * radius);
    return disc > 0.0 ? 2.0 * std::sqrt(disc) : 0.0;
}

/// Where origin + t dir crosses the box [min, max]: the length inside it.
double chordThroughBox(const Vec3d& origin, const Vec3d& dir, const Vec3d& min, const Vec3d& max)
{
    double t0 = 0.0, t1 = 1e30;
    for (int axis = 0; axis < 3; ++axis) {
        const double a = (min[axis] - origin[axis]) / dir[axis], b = (max[axis] - origin[axis]) / dir[axis];
        t0 = std::max(t0, std::min(a, b));
        t1 = std::min(t1, std::max(a, b));
    }
    return std::max(0.0, t1 - t0);
}

/// How far a ray from origin along dir (unit) runs through a cloud's shape.
using Chord = std::function<double(const Vec3d& origin, const Vec3d& dir)>;

/// A small scene: ground, a cloud, camera, sun and sky; rendered by either integrator.
struct FeatureScene {
    RenderSettings settings;
    SurfaceScene surfaces;
    std::unique_ptr<CloudLighting> lighting;
    std::unique_ptr<CloudVolume> volume;
    FrameToRender frame;

    FeatureScene(openvdb::FloatGrid::Ptr density, bool ground, const Vec3d& camera, const Vec3d& lookAt, const Vec3d& toSun)
    {
        if (ground) surfaces.addStatic(0, makeBox({{-60, -2, -60}, {60, 0, 60}}), Transform{});
        surfaces.commit();
        settings.camera.position = camera;
        settings.camera.lookAt = lookAt;
        settings.camera.fovDegrees = 40;
        settings.sun.direction = toSun;
        settings.image.width = 64;
        settings.image.height = 36;
        settings.image.samplesPerPixel = 1;
        // Each pixel its own samples alone: the standard errors below take
        // pixels as independent, which a filter sharing samples would not keep.
        settings.image.pixelFilterWidth = 0.0;
        settings.integrator.volumeStep = 0.1;
        frame.settings = &settings;
        frame.surfaces = &surfaces;
        frame.materials[0] = SurfaceMaterial{};
        frame.frame = 1;
        frame.camera = Camera::fromSettings(settings.camera, settings.image.width, settings.image.height);
        mDensity = std::move(density);
    }

    /// Lights the cloud with the settings as they are at the first render.
    void light()
    {
        if (volume) return;
        const SurfaceScene* occluders = &surfaces;
        lighting = std::make_unique<CloudLighting>(mDensity, settings.medium, settings.sun.direction,
                                                   [occluders](const Vec3d& o, const Vec3d& d) {
                                                       return occluders->occluded(o, d, 1e-3, std::numeric_limits<double>::max());
                                                   });
        volume = std::make_unique<CloudVolume>(*lighting, settings.medium, settings.integrator);
        frame.volume = volume.get();
    }

    RenderImage render(IntegratorKind kind, int samplesPerPixel, int seed = 0)
    {
        settings.integrator.kind = kind;
        settings.image.samplesPerPixel = samplesPerPixel;
        settings.image.seed = seed;
        light();
        return renderFrame(frame);
    }

    /// The pixels whose centre ray runs more than minChord through the cloud and meets no surface.
    std::vector<std::size_t> cloudPixels(const Chord& chord, double minChord) const
    {
        std::vector<std::size_t> pixels;
        for (int y = 0; y < settings.image.height; ++y)
            for (int x = 0; x < settings.image.width; ++x) {
                const Vec3d dir = frame.camera.direction(x + 0.5, y + 0.5);
                SurfaceHit hit;
                if (surfaces.intersect(frame.camera.position(), dir, 0.0, 1e30, hit)) continue;
                if (chord(frame.camera.position(), dir) > minChord) pixels.push_back(std::size_t(y) * settings.image.width + x);
            }
        return pixels;
    }

private:
    openvdb::FloatGrid::Ptr mDensity;
};

/// Mean luminance-like sum (r + g + b) / 3 over the given pixels.
double meanRadiance(const RenderImage& image, const std::vector<std::size_t>& pixels)
{
    double sum = 0.0;
    for (std::size_t p : pixels) sum += (image.rgba[4 * p] + image.rgba[4 * p + 1] + image.rgba[4 * p + 2]) / 3.0;
    return sum / double(pixels.size());
}

/// The standard error of meanRadiance of one of two independent renders, from their pixel differences.
double standardError(const RenderImage& a, const RenderImage& b, const std::vector<std::size_t>& pixels)
{
    double sumSquares = 0.0;
    for (std::size_t p : pixels) {
        const double d =
            ((a.rgba[4 * p] + a.rgba[4 * p + 1] + a.rgba[4 * p + 2]) - (b.rgba[4 * p] + b.rgba[4 * p + 1] + b.rgba[4 * p + 2])) /
            3.0;
        sumSquares += d * d;
    }
    // Var(a - b) = 2 Var(a) per pixel; the mean of n pixels has Var(a) / n.
    return std::sqrt(sumSquares / double(pixels.size()) / 2.0 / double(pixels.size()));
}

const Vec3d kCentre(0, 8, 0);
constexpr double kRadius = 6.0;

double chordThroughTheSphere(const Vec3d& origin, const Vec3d& dir) { return chordThroughSphere(origin, dir, kCentre, kRadius); }

openvdb::FloatGrid::Ptr uniformSphere(float density)
{
    return densityGrid(kCentre, kRadius + 0.5, 0.25,
                       [density](const Vec3d& p) { return (p - kCentre).length() < kRadius ? density : 0.0f; });
}

} // namespace

TEST_CASE("reference: an absorbing sphere shows the sky times exp(-sigma d)", "[render][reference]")
{
    // Albedo 0: nothing scatters, and each pixel is the sky seen through the
    // sphere's chord d. Delta tracking decides each sample's fate by coin:
    // 256 samples give the mean within about 0.03 a pixel; the average over
    // the sphere within 1%. One sample per pixel is drawn through its centre,
    // where d is known: 256 renders of one sample, each its own random stream.
    const openvdb::FloatGrid::Ptr sphere = uniformSphere(1.0f);
    FeatureScene scene(sphere, false, Vec3d(0, 8, 30), kCentre, Vec3d(1, 0.2, 0));
    scene.settings.medium.extinction = 0.15;
    scene.settings.medium.albedo = 0.0;
    const std::vector<std::size_t> pixels = scene.cloudPixels(chordThroughTheSphere, 1.0);
    REQUIRE(pixels.size() > 100);
    double measured = 0.0, expected = 0.0;
    const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sampler(*sphere);
    for (std::size_t p : pixels) {
        const int x = int(p % scene.settings.image.width), y = int(p / scene.settings.image.width);
        const Vec3d dir = scene.frame.camera.direction(x + 0.5, y + 0.5);
        // The optical depth of the grid as read (trilinear), by the midpoint rule in steps of 1/250 voxel.
        double depth = 0.0;
        for (double t = 22.0; t < 38.0; t += 1e-3)
            depth += sampler.wsSample(scene.frame.camera.position() + dir * (t + 5e-4)) * 1e-3;
        expected += skyRadiance(scene.settings, dir)[2] * std::exp(-0.15 * depth);
    }
    for (int render = 1; render <= 256; ++render) {
        const RenderImage image = scene.render(IntegratorKind::Reference, 1, render);
        for (std::size_t p : pixels) measured += image.rgba[4 * p + 2] / 256.0;
    }
    CHECK(measured == Approx(expected).epsilon(0.01));
}

namespace {

struct Agreement {
    double fast, reference, referenceError;
    double relative() const { return std::abs(fast - reference) / reference; }
};

/// The mean radiance of the sphere's pixels by both integrators; the
/// reference's standard error from a second, independent render.
Agreement compare(FeatureScene& scene, const Chord& chord, int referenceSamples)
{
    const std::vector<std::size_t> pixels = scene.cloudPixels(chord, 1.0);
    REQUIRE(pixels.size() > 100);
    const RenderImage fast = scene.render(IntegratorKind::Fast, 16);
    const RenderImage a = scene.render(IntegratorKind::Reference, referenceSamples, 1);
    const RenderImage b = scene.render(IntegratorKind::Reference, referenceSamples, 2);
    return {meanRadiance(fast, pixels), 0.5 * (meanRadiance(a, pixels) + meanRadiance(b, pixels)),
            standardError(a, b, pixels) / std::sqrt(2.0)};
}

/// One scattering event, the sun alone (the sky dark): both integrators
/// integrate the same light, the fast one with one octave.
void scatterOnceInSunlightAlone(FeatureScene& scene, double extinction)
{
    scene.settings.medium.extinction = extinction;
    scene.settings.medium.albedo = 0.9;
    scene.settings.sky.intensity = 0.0;
    scene.settings.integrator.multipleScattering.octaves = 1;
    scene.settings.integrator.maxBounces = 1;
}

} // namespace

TEST_CASE("reference: the fast integrator's single scattering is the reference's within its noise", "[render][reference]")
{
    // One scattering event, the sun alone (the sky dark, no ground to bounce
    // it): the fast march with one octave integrates the same light, up to its
    // light grid's resolution.
    FeatureScene scene(uniformSphere(1.0f), false, Vec3d(0, 8, 30), kCentre, Vec3d(1, 0.2, 0));
    scatterOnceInSunlightAlone(scene, 0.3);
    const Agreement single = compare(scene, chordThroughTheSphere, 64);
    INFO("single scattering: fast " << single.fast << ", reference " << single.reference << " +- " << single.referenceError);
    // Within three standard errors, and 1% for the light grid's interpolation.
    CHECK(std::abs(single.fast - single.reference) < 3.0 * single.referenceError + 0.01 * single.reference);
}

TEST_CASE("reference: in a dense cloud with structure finer than the light grids, the fast single scattering is the "
          "reference's, front-, side- and back-lit",
          "[render][reference]")
{
    // A sphere of dense lumps and gaps a voxel or two across (sharper than the
    // light grids' cells of two voxels): averaging its density over a cell
    // before the exponential lets through about 12% too much light lit from ahead.
    const GradientNoise noise(5);
    const openvdb::FloatGrid::Ptr lumpy = densityGrid(kCentre, kRadius + 0.5, 0.25, [&](const Vec3d& p) {
        if ((p - kCentre).length() >= kRadius) return 0.0f;
        return noise(float(p[0] * 1.7), float(p[1] * 1.7), float(p[2] * 1.7)) > 0.0f ? 3.0f : 0.1f;
    });
    const Vec3d camera(0, 8, 30);
    for (const Vec3d& toSun : {Vec3d(0.3, 0.5, 1.0), Vec3d(1, 0.2, 0), Vec3d(0.3, 0.4, -1.0)}) {
        FeatureScene scene(lumpy, false, camera, kCentre, toSun);
        scatterOnceInSunlightAlone(scene, 1.0);
        const Agreement single = compare(scene, chordThroughTheSphere, 64);
        INFO("sun towards " << toSun << ": fast " << single.fast << ", reference " << single.reference << " +- "
                            << single.referenceError);
        CHECK(std::abs(single.fast - single.reference) < 3.0 * single.referenceError + 0.02 * single.reference);
    }
}

TEST_CASE("reference: in a thick cloud, the fast integrator with multiple scattering by paths is the reference's within "
          "5%, front-, side- and back-lit, however coarse its lattice",
          "[render][reference]")
{
    // Optical radius 12, albedo 0.97, one strongly forward lobe, the sun
    // alone: most of the light the camera sees has scattered many times.
    const Vec3d camera(0, 8, 30);
    for (const Vec3d& toSun : {Vec3d(0.3, 0.5, 1.0), Vec3d(1, 0.2, 0), Vec3d(0.3, 0.4, -1.0)}) {
        FeatureScene scene(uniformSphere(2.0f), false, camera, kCentre, toSun);
        scene.settings.medium.extinction = 1.0;
        scene.settings.medium.albedo = 0.97;
        scene.settings.medium.anisotropy = 0.75;
        scene.settings.sky.intensity = 0.0;
        scene.settings.integrator.multipleScattering.method = MultipleScatteringMethod::Paths;
        // 256 samples: the reference's own noise (about 1%) well inside the bound.
        const Agreement all = compare(scene, chordThroughTheSphere, 256);
        // Points 24 voxels apart, the sphere's radius: the paths' light,
        // gathered where they scatter, keeps its mean over the image. Traced
        // from the lattice's points themselves, it would come out well short
        // of the reference on so coarse a lattice, beyond this bound.
        scene.settings.integrator.multipleScattering.pathSpacing = 24;
        const double coarse = meanRadiance(scene.render(IntegratorKind::Fast, 16), scene.cloudPixels(chordThroughTheSphere, 1.0));
        INFO("sun towards " << toSun << ": fast " << all.fast << ", with a coarse lattice " << coarse << ", reference "
                            << all.reference << " +- " << all.referenceError);
        CHECK(all.relative() < 0.05);
        CHECK(std::abs(coarse - all.reference) < 0.05 * all.reference);
    }
}

TEST_CASE("reference: images are identical for 1 and 2 threads", "[render][reference]")
{
    FeatureScene scene(uniformSphere(1.0f), true, Vec3d(0, 8, 30), kCentre, Vec3d(1, 0.2, 0));
    const auto sameForOneAndTwoThreads = [&](IntegratorKind kind, int samples) {
        RenderImage one, two;
        {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
            one = scene.render(kind, samples);
        }
        {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
            two = scene.render(kind, samples);
        }
        return one.rgba == two.rgba;
    };
    CHECK(sameForOneAndTwoThreads(IntegratorKind::Reference, 4));
    // The fast integrator's light scattered many times, traced by the reference's paths.
    scene.settings.integrator.multipleScattering.method = MultipleScatteringMethod::Paths;
    CHECK(sameForOneAndTwoThreads(IntegratorKind::Fast, 1));
}

TEST_CASE("reference: every pixel takes every sample, whatever the scene's adaptive sampling", "[render][reference]")
{
    // Sampled adaptively, a pixel whose first path found no sunlit scattering
    // would keep that one dark sample: on a lumpy cloud lit from behind, the
    // reference would come out several percent dark, and no number of samples
    // would mend it.
    FeatureScene scene(uniformSphere(1.0f), true, Vec3d(0, 8, 30), kCentre, Vec3d(1, 0.2, 0));
    const RenderImage everySample = scene.render(IntegratorKind::Reference, 8);
    scene.settings.image.adaptiveThreshold = 0.06;
    CHECK(scene.render(IntegratorKind::Reference, 8).rgba == everySample.rgba);
}

TEST_CASE("reference: its noise falls as one over the square root of the samples", "[render][reference]")
{
    FeatureScene scene(uniformSphere(1.0f), true, Vec3d(0, 8, 30), kCentre, Vec3d(1, 0.2, 0));
    scene.settings.medium.extinction = 0.5;
    scene.settings.medium.albedo = 0.95;
    const std::vector<std::size_t> pixels = scene.cloudPixels(chordThroughTheSphere, 1.0);
    const auto noise = [&](int samples) {
        return standardError(scene.render(IntegratorKind::Reference, samples, 1),
                             scene.render(IntegratorKind::Reference, samples, 2), pixels);
    };
    const double coarse = noise(16), fine = noise(64);
    INFO("standard error of the mean: " << coarse << " at 16 samples, " << fine << " at 64");
    CHECK(coarse / fine == Approx(2.0).epsilon(0.2));
}

TEST_CASE("reference: fast and reference agree within 10% on a sphere of cloud over the ground, sun from the side",
          "[render][reference]")
{
    // All the light: multiple scattering of the sun, the sky and the ground's bounce.
    FeatureScene scene(uniformSphere(1.0f), true, Vec3d(0, 8, 30), kCentre, Vec3d(1, 0.2, 0));
    scene.settings.medium.extinction = 0.5;
    scene.settings.medium.albedo = 0.95;
    scene.settings.medium.anisotropy = 0.6;
    const Agreement all = compare(scene, chordThroughTheSphere, 256);
    INFO("sphere lit from the side: fast " << all.fast << ", reference " << all.reference << " +- " << all.referenceError);
    CHECK(all.relative() < 0.1);
}

TEST_CASE("reference: fast and reference agree within 10% on a constant-density box over the ground, sun from above",
          "[render][reference]")
{
    // A 12 x 6 x 10 block of density 1, seen from the side: its top lit by
    // the sun, its base by the sunlit ground.
    const openvdb::FloatGrid::Ptr box = densityGrid(kCentre, 7.0, 0.25, [](const Vec3d& p) {
        return std::abs(p[0]) < 6 && std::abs(p[1] - kCentre[1]) < 3 && std::abs(p[2]) < 5 ? 1.0f : 0.0f;
    });
    FeatureScene scene(box, true, Vec3d(0, 8, 30), kCentre, Vec3d(0.4, 0.8, 0.3));
    scene.settings.medium.extinction = 0.3;
    scene.settings.medium.albedo = 0.9;
    scene.settings.medium.anisotropy = 0.6;
    const Agreement all = compare(
        scene,
        [](const Vec3d& origin, const Vec3d& dir) {
            return chordThroughBox(origin, dir, kCentre - Vec3d(6, 3, 5), kCentre + Vec3d(6, 3, 5));
        },
        64);
    INFO("box lit from above: fast " << all.fast << ", reference " << all.reference << " +- " << all.referenceError);
    CHECK(all.relative() < 0.1);
}

TEST_CASE("reference: a cloud's shadow never brightens the ground and is as dark as the reference's", "[render][reference]")
{
    // A sphere of cloud seen from above, the sun high beside it: its shadow
    // falls on the ground in view. The ground's pixels whose camera ray misses
    // the sphere, compared with the same frame without the cloud, and those
    // in its shadow (the ray from the ground to the sun runs at least 4 units
    // through the sphere) with the reference's: thin, medium and thick.
    const Vec3d toSun = Vec3d(0.5, 1.0, 0.3).unitSafe();
    const auto scene = [&](float density) {
        auto s = std::make_unique<FeatureScene>(uniformSphere(density), true, Vec3d(0, 40, 26), Vec3d(-4, 0, -2), toSun);
        s->settings.medium.extinction = 0.5;
        s->settings.medium.albedo = 0.95;
        s->settings.medium.anisotropy = 0.6;
        s->settings.image.width = 128;
        s->settings.image.height = 72;
        s->frame.camera = Camera::fromSettings(s->settings.camera, 128, 72);
        return s;
    };
    const std::unique_ptr<FeatureScene> clear = scene(1e-6f);
    const RenderImage without = clear->render(IntegratorKind::Fast, 1);
    const int width = clear->settings.image.width, height = clear->settings.image.height;
    std::vector<std::size_t> ground, shadow;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const Vec3d origin = clear->frame.camera.position(), dir = clear->frame.camera.direction(x + 0.5, y + 0.5);
            SurfaceHit hit;
            if (!clear->surfaces.intersect(origin, dir, 0.0, 1e30, hit) || chordThroughTheSphere(origin, dir) > 0.0) continue;
            const std::size_t p = std::size_t(y) * width + x;
            ground.push_back(p);
            if (chordThroughTheSphere(hit.position, toSun) > 4.0) shadow.push_back(p);
        }
    REQUIRE(ground.size() > 1000);
    REQUIRE(shadow.size() > 100);

    for (const float density : {0.3f, 1.0f, 3.0f}) {
        const std::unique_ptr<FeatureScene> cloudy = scene(density);
        const RenderImage withCloud = cloudy->render(IntegratorKind::Fast, 1);
        double brightest = 0.0; // the largest ratio of a ground pixel with the cloud to without it
        for (std::size_t p : ground)
            for (int c = 0; c < 3; ++c)
                brightest = std::max(brightest, double(withCloud.rgba[4 * p + c] / without.rgba[4 * p + c]));
        INFO("density " << density << ": the ground with the cloud, at its brightest: " << brightest
                        << " x its light without it");
        CHECK(brightest <= 1.0 + 1e-6);

        const RenderImage fast = cloudy->render(IntegratorKind::Fast, 16);
        const RenderImage a = cloudy->render(IntegratorKind::Reference, 64, 1),
                          b = cloudy->render(IntegratorKind::Reference, 64, 2);
        const double reference = 0.5 * (meanRadiance(a, shadow) + meanRadiance(b, shadow));
        INFO("in the shadow: fast " << meanRadiance(fast, shadow) << ", reference " << reference << " +- "
                                    << standardError(a, b, shadow) / std::sqrt(2.0) << ", unshadowed "
                                    << meanRadiance(without, shadow));
        CHECK(meanRadiance(fast, shadow) == Approx(reference).epsilon(0.1));
    }
}
