#include "test_meshes.h"

#include <vfield/mesh/procedural.h>
#include <vfield/render/embree/camera_samples.h>
#include <vfield/render/embree/renderer.h>
#include <vfield/render/frame_image.h>

#include <catch2/catch.hpp>

#include <OpenImageIO/imagebufalgo.h>

#include <openvdb/tools/Composite.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

using namespace vfield;

namespace {

/// A FloatGrid of constant density over the world box [min, max] (voxel centres inside).
openvdb::FloatGrid::Ptr constantBox(const Vec3d& min, const Vec3d& max, double voxel, float density)
{
    openvdb::initialize();
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
    const openvdb::Coord lo = openvdb::Coord::round(min / voxel + 0.5), hi = openvdb::Coord::round(max / voxel - 0.5);
    grid->tree().fill(openvdb::CoordBBox(lo, hi), density, true);
    return grid;
}

RenderSettings medium(double extinction, double albedo, double anisotropy, double step)
{
    RenderSettings settings;
    settings.medium.extinction = extinction;
    settings.medium.albedo = albedo;
    settings.medium.anisotropy = anisotropy;
    settings.integrator.volumeStep = step;
    settings.integrator.multipleScattering.octaves = 1; // single scattering: what the analytic results describe
    return settings;
}

/// A density grid lit (shadowed by occluders, if any) and ready to march.
struct LitCloud {
    CloudLighting lighting;
    CloudVolume volume;

    LitCloud(openvdb::FloatGrid::ConstPtr grid, const RenderSettings& settings, const Vec3d& toSun, const SurfaceScene* occluders)
        : lighting(std::move(grid), settings.medium, toSun, sunBlockedBy(occluders)),
          volume(lighting, settings.medium, settings.integrator)
    {}

    static CloudLighting::Occlusion sunBlockedBy(const SurfaceScene* occluders)
    {
        if (!occluders) return {};
        return [occluders](const Vec3d& origin, const Vec3d& dir) {
            return occluders->occluded(origin, dir, 1e-3, std::numeric_limits<double>::max());
        };
    }
};

struct SmallScene {
    RenderSettings settings;
    SurfaceScene surfaces;
    FrameToRender frame;

    SmallScene()
    {
        surfaces.addStatic(0, makeBox({{-20, -2, -20}, {20, 0, 20}}), Transform{});
        surfaces.addStatic(1, makeBox({{-2, 0, -2}, {2, 6, 2}}), Transform{});
        surfaces.commit();
        settings.camera.position = Vec3d(0, 8, 30);
        settings.camera.lookAt = Vec3d(0, 2, 0);
        frame.settings = &settings;
        frame.surfaces = &surfaces;
        frame.materials[0] = SurfaceMaterial::terrain();
        settings.image.width = 96;
        settings.image.height = 54;
        settings.image.samplesPerPixel = 2;
        frame.frame = 7;
        frame.camera = Camera::fromSettings(settings.camera, settings.image.width, settings.image.height);
    }
};

} // namespace

TEST_CASE("render: an empty volume renders exactly like surfaces alone", "[render]")
{
    SmallScene scene;
    const RenderImage surfacesOnly = renderFrame(scene.frame);
    const LitCloud empty(openvdb::FloatGrid::create(0.0f), scene.settings, scene.settings.sun.direction, &scene.surfaces);
    REQUIRE(empty.volume.empty());
    scene.frame.volume = &empty.volume;
    const RenderImage withVolume = renderFrame(scene.frame);
    CHECK(withVolume.rgba == surfacesOnly.rgba);
    CHECK(withVolume.depth == surfacesOnly.depth);
}

TEST_CASE("render: transmittance through a constant-density box is exp(-sigma d)", "[render]")
{
    // Density 0.8 over x in [-5, 5]: d = 10, sigma = 0.25 x 0.8.
    const auto grid = constantBox({-5, -3, -3}, {5, 3, 3}, 0.1, 0.8f);
    const LitCloud cloud(grid, medium(0.25, 0.9, 0.0, 0.05), Vec3d(0, 1, 0), nullptr);
    const CloudVolume& volume = cloud.volume;
    for (double jitter : {0.0, 0.37, 0.99}) {
        const CloudVolume::Segment s = volume.march({-20, 0.01, 0.02}, {1, 0, 0}, 0.0, 1e9, jitter, Vec3d(0.0), Vec3d(0.0));
        CHECK(s.transmittance == Approx(std::exp(-0.25 * 0.8 * 10.0)).epsilon(0.01));
    }
    // Stopping at a surface 4 units into the box (whose voxels span x from -4.95): d = 4.
    const CloudVolume::Segment s = volume.march({-20, 0.01, 0.02}, {1, 0, 0}, 0.0, 19.05, 0.5, Vec3d(0.0), Vec3d(0.0));
    CHECK(s.transmittance == Approx(std::exp(-0.25 * 0.8 * 4.0)).epsilon(0.01));
}

TEST_CASE("render: a slab lit from behind matches analytic single scattering", "[render]")
{
    // A slab z in [0, L] seen along +z with the sun straight behind it: every
    // depth z sees e^(-sigma_t (L - z)) of the sun and passes e^(-sigma_t z) on,
    // so L_out = sigma_s E p(0) L e^(-sigma_t L), p the Henyey-Greenstein phase.
    const double rho = 0.5, extinction = 1.0, albedo = 0.8, g = 0.4, length = 2.0, sun = 3.0;
    const auto grid = constantBox({-4, -4, 0}, {4, 4, length}, 0.02, float(rho));
    const LitCloud cloud(grid, medium(extinction, albedo, g, 0.01), Vec3d(0, 0, 1), nullptr);
    const CloudVolume& volume = cloud.volume;
    const CloudVolume::Segment s = volume.march({0.003, 0.001, -10}, {0, 0, 1}, 0.0, 1e9, 0.5, Vec3d(sun), Vec3d(0.0));
    const double sigmaT = extinction * rho;
    const double expected = albedo * sigmaT * sun * henyeyGreenstein(1.0, g) * length * std::exp(-sigmaT * length);
    // Tolerance 2%: the sun's transmittance is read from a coarser grid, trilinearly.
    CHECK(s.radiance[0] == Approx(expected).epsilon(0.02));
    CHECK(s.transmittance == Approx(std::exp(-sigmaT * length)).epsilon(0.01));
}

TEST_CASE("render: the phase function integrates to one", "[render]")
{
    for (double g : {-0.5, 0.0, 0.3, 0.8}) {
        double integral = 0;
        const int n = 20000;
        for (int i = 0; i < n; ++i) {
            const double mu = -1.0 + (i + 0.5) * 2.0 / n;
            integral += henyeyGreenstein(mu, g) * 2.0 * M_PI * (2.0 / n);
        }
        CHECK(integral == Approx(1.0).epsilon(1e-3));
    }
}

TEST_CASE("render: a faint cloud straddling the ground leaves the lit ground as it is", "[render]")
{
    // The cloud's box reaches 1 unit into the ground, where grid points are
    // hidden from the sun; surfaces must read the cloud's transmittance only
    // (their own shadow ray finds the ground), or they darken in blocks.
    SmallScene scene;
    const RenderImage without = renderFrame(scene.frame);
    const LitCloud faint(constantBox({-12, -1, -12}, {12, 3, 12}, 0.5, 1e-6f), scene.settings, scene.settings.sun.direction,
                         &scene.surfaces);
    scene.frame.volume = &faint.volume;
    const RenderImage with = renderFrame(scene.frame);
    double worst = 0.0;
    for (std::size_t i = 0; i < with.rgba.size(); ++i) worst = std::max(worst, double(std::abs(with.rgba[i] - without.rgba[i])));
    CHECK(worst < 1e-3);
}

TEST_CASE("render: a cloud's shadow on a surface is exp(-sigma tau) of the cloud towards the sun, however large its box",
          "[render]")
{
    // A sphere of constant density, and a speck of cloud 150 units away that
    // stretches the box of the light grids until their cells are 2.5 units
    // wide: read from them, the sphere's shadow would come out as nested squares.
    openvdb::initialize();
    const double radius = 4.0, voxel = 0.25, sigma = 1.0;
    const float density = 0.2f;
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
    const int reach = int(std::ceil(radius / voxel));
    for (openvdb::Coord c(-reach); c.x() <= reach; ++c.x())
        for (c.y() = -reach; c.y() <= reach; ++c.y())
            for (c.z() = -reach; c.z() <= reach; ++c.z())
                if ((c.asVec3d() * voxel).length() < radius) grid->tree().setValue(c, density);
    grid->tree().setValue(openvdb::Coord(int(150.0 / voxel), 0, 0), density);

    const Vec3d toSun = Vec3d(0.3, 1.0, 0.2).unit();
    const CloudLighting lighting(grid, medium(sigma, 0.9, 0.0, 0.1).medium, toSun, {});
    double worst = 0.0;
    int shadowed = 0;
    for (double x = -8.0; x <= 8.0; x += 0.31)
        for (double z = -8.0; z <= 8.0; z += 0.31) {
            const Vec3d ground(x, -8.0, z);
            // The chord of the sun's ray from the ground through the sphere.
            const double along = -ground.dot(toSun), miss2 = ground.lengthSqr() - along * along;
            const double chord = miss2 < radius * radius ? 2.0 * std::sqrt(radius * radius - miss2) : 0.0;
            if (std::abs(std::sqrt(miss2) - radius) < 1.0) continue; // the voxelized rim
            shadowed += chord > 0.0;
            worst = std::max(worst, std::abs(lighting.sunTransmittance(ground) - std::exp(-sigma * density * chord)));
            CHECK(lighting.sunTransmittance(Vec3d(x, 8.0, z)) == 1.0); // above the cloud
        }
    CHECK(shadowed > 300);
    CHECK(worst < 0.02);
}

TEST_CASE("render: a cloud in a surface's shadow gets no sun", "[render]")
{
    // A cloud under a roof: lit by the sun where it reaches past the roof's
    // edge, and by the sky alone beneath it.
    SurfaceScene roof;
    roof.addStatic(0, makeBox({{-10, 5, -10}, {0, 5.5, 10}}), Transform{});
    roof.commit();
    RenderSettings settings = medium(1.0, 0.9, 0.0, 0.05);
    const LitCloud cloud(constantBox({-4, 0, -1}, {4, 2, 1}, 0.1, 0.5f), settings, Vec3d(0, 1, 0), &roof);
    const auto seen = [&](double x) {
        return cloud.volume.march({x, 1, -10}, {0, 0, 1}, 0.0, 1e9, 0.5, Vec3d(1.0), Vec3d(0.0)).radiance[0];
    };
    CHECK(seen(-2.0) < 1e-6);
    CHECK(seen(2.0) > 0.02);
}

TEST_CASE("render: a cloud behind a surface does not show through it", "[render]")
{
    SmallScene scene;
    const RenderImage surfacesOnly = renderFrame(scene.frame);
    // A dense cloud behind the pillar, as seen from the camera.
    const LitCloud cloud(constantBox({-3, 1, -12}, {3, 5, -6}, 0.25, 2.0f), scene.settings, scene.settings.sun.direction,
                         &scene.surfaces);
    scene.frame.volume = &cloud.volume;
    const RenderImage withCloud = renderFrame(scene.frame);
    // The pillar's centre pixel: the same in both; beside the pillar the cloud shows.
    const auto pixel = [&](const RenderImage& image, int x, int y) { return image.rgba[4 * (std::size_t(y) * image.width + x)]; };
    CHECK(pixel(withCloud, 48, 24) == pixel(surfacesOnly, 48, 24));
    CHECK(withCloud.rgba != surfacesOnly.rgba);
}

TEST_CASE("render: images are identical for 1 and 2 threads", "[render]")
{
    SmallScene scene;
    const LitCloud cloud(constantBox({-6, 2, -3}, {6, 6, 3}, 0.25, 0.6f), scene.settings, scene.settings.sun.direction,
                         &scene.surfaces);
    scene.frame.volume = &cloud.volume;
    RenderImage one, two;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = renderFrame(scene.frame);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = renderFrame(scene.frame);
    }
    CHECK(one.rgba == two.rgba);
}

TEST_CASE("render: a shot that does not move renders identical frames; an animated or another seed draws other noise", "[render]")
{
    SmallScene scene;
    scene.settings.integrator.multipleScattering.method = MultipleScatteringMethod::Paths; // its paths are drawn too
    scene.settings.integrator.multipleScattering.pathsPerFrame = 2000;
    const LitCloud cloud(constantBox({-6, 2, -3}, {6, 6, 3}, 0.25, 0.6f), scene.settings, scene.settings.sun.direction,
                         &scene.surfaces);
    scene.frame.volume = &cloud.volume;
    const auto renderAt = [&](int frame) {
        scene.frame.frame = frame;
        return renderFrame(scene.frame).rgba;
    };
    const std::vector<float> first = renderAt(1);
    CHECK(renderAt(2) == first);
    CHECK(renderAt(240) == first);
    scene.settings.image.seed = 5;
    CHECK(renderAt(1) != first);
    scene.settings.image.animatedSeed = true;
    CHECK(renderAt(1) != renderAt(2));
}

TEST_CASE("render: a cloud that changes in one place keeps the light and the noise it had everywhere else", "[render]")
{
    // A wisp beside the cloud moves towards the camera between two frames,
    // and the cloud's box grows with it: the march's steps, the paths' rays
    // and the lattice that gathers their light are laid out independently of
    // the box, so what stays put renders as it did. Laid out from the box's
    // faces, every pixel of the cloud took other samples and other paths.
    SmallScene scene;
    scene.settings.integrator.multipleScattering.method = MultipleScatteringMethod::Paths;
    scene.settings.integrator.multipleScattering.pathsPerFrame = 2000;
    scene.settings.integrator.multipleScattering.pathFramesAround = 0;
    const auto renderWithWispAt = [&](double z) {
        openvdb::FloatGrid::Ptr grid = constantBox({-6, 2, -3}, {4, 6, 3}, 0.25, 0.6f);
        openvdb::tools::compMax(*grid, *constantBox({9, 6, z}, {10, 7, z + 1}, 0.25, 0.6f));
        const LitCloud cloud(grid, scene.settings, scene.settings.sun.direction, &scene.surfaces);
        scene.frame.volume = &cloud.volume;
        return renderFrame(scene.frame);
    };
    scene.frame.passes = true; // for the cloud's own coverage
    const RenderImage before = renderWithWispAt(2.0), after = renderWithWispAt(4.0);
    // The cloud's pixels well left of the wisp's (about x = 70).
    std::size_t cloudPixels = 0, asBefore = 0;
    double worst = 0.0;
    for (int y = 0; y < before.height; ++y)
        for (int x = 0; x < 50; ++x) {
            const std::size_t pixel = std::size_t(y) * before.width + x;
            if (before.passes.cloud[4 * pixel + 3] < 0.05f) continue;
            ++cloudPixels;
            double largest = 0.0;
            for (int c = 0; c < 3; ++c)
                largest = std::max(largest, std::abs(double(linearToSrgb(after.rgba[4 * pixel + c])) -
                                                     double(linearToSrgb(before.rgba[4 * pixel + c]))));
            asBefore += largest < 0.5 / 255.0;
            worst = std::max(worst, largest * 255.0);
        }
    INFO(asBefore << " of " << cloudPixels << " pixels of the cloud as before; worst " << worst << " steps");
    CHECK(cloudPixels > 150);
    CHECK(asBefore > cloudPixels * 9 / 10);
}

TEST_CASE("render: the pixel filter steadies fine detail that shifts by a fraction of a pixel", "[render]")
{
    // A cloud of lumps a voxel across, half a pixel, moved by a voxel
    // between two frames as a cloud's detail drifts: with a box, each pixel's
    // two samples see other lumps and the cloud boils; shared among
    // neighbours by the Gaussian, the same samples change its pixels by a
    // quarter less or more, and its light is what it was.
    SmallScene scene;
    scene.frame.passes = true; // for the cloud's coverage
    constexpr double kVoxel = 0.2;
    const auto lumps = [&](int shift) {
        openvdb::initialize();
        openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
        grid->setTransform(openvdb::math::Transform::createLinearTransform(kVoxel));
        for (int i = -30; i <= 30; ++i)
            for (int j = 10; j <= 30; ++j)
                for (int k = -10; k <= 10; ++k)
                    if ((i * 7 + j * 13 + k * 5) % 3 == 0) grid->tree().setValue(openvdb::Coord(i + shift, j, k), 2.0f);
        return grid;
    };
    const auto renderShifted = [&](int shift) {
        const LitCloud cloud(lumps(shift), scene.settings, scene.settings.sun.direction, &scene.surfaces);
        scene.frame.volume = &cloud.volume;
        return renderFrame(scene.frame);
    };
    // Over the pixels the cloud covers, in 8-bit steps, and its light.
    const auto meanChange = [](const RenderImage& a, const RenderImage& b) {
        double sum = 0.0;
        std::size_t values = 0;
        for (std::size_t pixel = 0; pixel < a.depth.size(); ++pixel) {
            if (a.passes.cloud[4 * pixel + 3] < 0.05f) continue;
            for (int c = 0; c < 3; ++c, ++values)
                sum += std::abs(double(linearToSrgb(a.rgba[4 * pixel + c])) - double(linearToSrgb(b.rgba[4 * pixel + c])));
        }
        return 255.0 * sum / double(values);
    };
    const auto light = [](const RenderImage& image) {
        double sum = 0.0;
        for (std::size_t i = 0; i < image.rgba.size(); ++i) sum += i % 4 != 3 ? image.rgba[i] : 0.0f;
        return sum;
    };
    scene.settings.image.pixelFilterWidth = 0.0;
    const RenderImage boxBefore = renderShifted(0), boxAfter = renderShifted(1);
    scene.settings.image.pixelFilterWidth = 2.0;
    const RenderImage gaussianBefore = renderShifted(0), gaussianAfter = renderShifted(1);
    const double box = meanChange(boxBefore, boxAfter), gaussian = meanChange(gaussianBefore, gaussianAfter);
    INFO("the cloud's pixels change by " << box << " steps with a box, " << gaussian << " with the Gaussian");
    CHECK(box > 2.0);
    CHECK(gaussian < 0.75 * box);
    CHECK(light(gaussianBefore) == Approx(light(boxBefore)).epsilon(0.01));
}

TEST_CASE("render: the pixel filter leaves a pixel's one sample through its centre to that pixel alone", "[render]")
{
    // One sample a pixel goes through its centre, a pixel away from every
    // neighbour's: the Gaussian 2 pixels wide is 0 there, and the image is the box's.
    SmallScene scene;
    scene.settings.image.samplesPerPixel = 1;
    const LitCloud cloud(constantBox({-6, 2, -3}, {6, 6, 3}, 0.25, 0.6f), scene.settings, scene.settings.sun.direction,
                         &scene.surfaces);
    scene.frame.volume = &cloud.volume;
    const RenderImage gaussian = renderFrame(scene.frame);
    scene.settings.image.pixelFilterWidth = 0.0;
    CHECK(renderFrame(scene.frame).rgba == gaussian.rgba);
}

TEST_CASE("render: pixels stand out by their display values' difference from a neighbour's, or their coverage's", "[render]")
{
    // Columns 0-3 and 4-7: a step in linear value, or in coverage.
    const auto step = [](float left, float right, float leftAlpha, float rightAlpha) {
        RenderImage image;
        image.width = 8;
        image.height = 3;
        image.depth.assign(24, 1.0f);
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 8; ++x) {
                const float v = x < 4 ? left : right, a = x < 4 ? leftAlpha : rightAlpha;
                image.rgba.insert(image.rgba.end(), {v, v, v, a});
            }
        return image;
    };
    const auto flaggedColumns = [](const std::vector<uint8_t>& flags) {
        std::vector<int> columns;
        for (int x = 0; x < 8; ++x) {
            const bool allRows = flags[std::size_t(x)] && flags[std::size_t(8 + x)] && flags[std::size_t(16 + x)];
            const bool noRow = !flags[std::size_t(x)] && !flags[std::size_t(8 + x)] && !flags[std::size_t(16 + x)];
            REQUIRE((allRows || noRow));
            if (allRows) columns.push_back(x);
        }
        return columns;
    };
    // 0.20 -> 0.25 is 0.484 -> 0.537 in sRGB; 0.90 -> 0.95 only 0.955 -> 0.977:
    // the same linear step shows in the shadows, not in the highlights.
    CHECK(flaggedColumns(pixelsThatStandOut(step(0.20f, 0.25f, 1, 1), 0.04)) == std::vector<int>{3, 4});
    CHECK(flaggedColumns(pixelsThatStandOut(step(0.90f, 0.95f, 1, 1), 0.04)).empty());
    CHECK(flaggedColumns(pixelsThatStandOut(step(0.0f, 0.0f, 0, 0.5f), 0.04)) == std::vector<int>{3, 4});
    CHECK(flaggedColumns(pixelsThatStandOut(step(0.5f, 0.5f, 1, 1), 0.0)).empty());
}

TEST_CASE("render: adaptive sampling gives every sample to the pixels that stand out or the cloud covers, and one to the "
          "others",
          "[render]")
{
    SmallScene scene;
    scene.settings.image.samplesPerPixel = 4;
    scene.settings.image.pixelFilterWidth = 0.0; // each pixel its own samples alone: which took which shows
    // Painted ground: terrain's noise is drawn at a pixel's first sample on
    // it in each pass, which for the pixels refined is then their second.
    scene.frame.materials[0] = SurfaceMaterial::painted(Vec3d(0.3, 0.5, 0.2));
    const LitCloud cloud(constantBox({-6, 2, -3}, {6, 6, 3}, 0.25, 0.6f), scene.settings, scene.settings.sun.direction,
                         &scene.surfaces);
    scene.frame.volume = &cloud.volume;
    const RenderImage every = renderFrame(scene.frame);
    // A threshold of 1 takes no display difference: the first samples alone,
    // and with them the cloud's coverage of each pixel.
    scene.settings.image.adaptiveThreshold = 1.0;
    scene.frame.passes = true;
    const RenderImage first = renderFrame(scene.frame);
    scene.frame.passes = false;
    scene.settings.image.adaptiveThreshold = 0.05;
    const RenderImage adaptive = renderFrame(scene.frame);
    std::vector<uint8_t> standOut = pixelsThatStandOut(first, 0.05);
    std::size_t clouded = 0;
    for (std::size_t pixel = 0; pixel < standOut.size(); ++pixel)
        if (first.passes.cloud[4 * pixel + 3] > 0.05f) {
            clouded += !standOut[pixel];
            standOut[pixel] = 1;
        }

    const auto samePixel = [](const RenderImage& a, const RenderImage& b, std::size_t pixel) {
        return std::equal(&a.rgba[4 * pixel], &a.rgba[4 * pixel + 4], &b.rgba[4 * pixel]) && a.depth[pixel] == b.depth[pixel];
    };
    std::size_t refined = 0, asEvery = 0, asFirst = 0;
    for (std::size_t pixel = 0; pixel < standOut.size(); ++pixel) {
        if (standOut[pixel]) {
            ++refined;
            asEvery += samePixel(adaptive, every, pixel);
        } else {
            asFirst += samePixel(adaptive, first, pixel);
        }
    }
    // The box's and the pillar's outlines stand out, and the whole cloud is
    // refined, its smooth inside too; the ground and the sky are not.
    CHECK(clouded > standOut.size() / 50);
    CHECK(refined > standOut.size() / 10);
    CHECK(refined < standOut.size() / 2);
    CHECK(asEvery == refined);
    CHECK(asFirst == standOut.size() - refined);
    CHECK(first.rgba != every.rgba);

    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    CHECK(renderFrame(scene.frame).rgba == adaptive.rgba);
}

TEST_CASE("render: EXR frames hold linear Rec.709 half-float colour and 32-bit depth, and PNG is the view's", "[render]")
{
    SmallScene scene;
    const RenderImage image = renderFrame(scene.frame);
    const std::string dir = test::scratchDir("render-exr");
    const DisplayView standard(ViewSettings{"Standard", 0.0});
    writeFrameImage(image, dir + "/f.exr", standard);
    writeFrameImage(image, dir + "/f.png", standard);
    OIIO::ImageBuf exr(dir + "/f.exr");
    REQUIRE(exr.read());
    const OIIO::ImageSpec& spec = exr.spec();
    CHECK(spec.nchannels == 5);
    CHECK(spec.channelnames == std::vector<std::string>{"R", "G", "B", "A", "Z"});
    // Colours and alpha as half floats; depth as 32-bit floats (half has 0.25 units of precision at 300 units).
    CHECK(exr.nativespec().channelformat(0) == OIIO::TypeDesc::HALF);
    CHECK(exr.nativespec().channelformat(3) == OIIO::TypeDesc::HALF);
    CHECK(exr.nativespec().channelformat(4) == OIIO::TypeDesc::FLOAT);
    // The header names the working space and its primaries, as OpenEXR's chromaticities.
    CHECK(spec.get_string_attribute("colorSpace") == "Linear Rec.709");
    const OIIO::ParamValue* chromaticities = spec.find_attribute("chromaticities");
    REQUIRE(chromaticities);
    CHECK(chromaticities->get_float_indexed(0) == 0.64f);   // red x
    CHECK(chromaticities->get_float_indexed(7) == 0.3290f); // white y: D65
    // The pillar's centre: depth is the camera distance, colour the linear value.
    const int x = 48, y = 24;
    const float* linear = &image.rgba[4 * (std::size_t(y) * image.width + x)];
    CHECK(exr.getchannel(x, y, 0, 4) == image.depth[std::size_t(y) * image.width + x]);
    CHECK(exr.getchannel(x, y, 0, 0) == Approx(linear[0]).epsilon(2e-3));
    CHECK(exr.getchannel(x, y, 0, 3) == 1.0f);
    OIIO::ImageBuf png(dir + "/f.png");
    REQUIRE(png.read());
    const double srgb = linear[0] <= 0.0031308 ? 12.92 * linear[0] : 1.055 * std::pow(linear[0], 1 / 2.4) - 0.055;
    CHECK(png.getchannel(x, y, 0, 0) == Approx(srgb).margin(1.0 / 255));
}

TEST_CASE("render passes: the cloud over the surfaces is the beauty, by oiiotool --over, for both integrators", "[render]")
{
    SmallScene scene;
    scene.frame.passes = true;
    scene.settings.image.transparentSky = true; // the surfaces' alpha matters too
    const LitCloud cloud(constantBox({-6, 2, -3}, {6, 6, 3}, 0.25, 0.6f), scene.settings, scene.settings.sun.direction,
                         &scene.surfaces);
    scene.frame.volume = &cloud.volume;
    const std::string dir = test::scratchDir("render-passes-over");
    for (const IntegratorKind kind : {IntegratorKind::Fast, IntegratorKind::Reference}) {
        INFO(enumName(kind));
        scene.settings.integrator.kind = kind;
        const std::string frame = dir + "/frame.exr", over = dir + "/over.exr", beauty = dir + "/beauty.exr";
        writeFrameImage(renderFrame(scene.frame), frame, DisplayView(scene.settings.view), ExrDepth::Float);
        const std::string composite = "oiiotool " + frame + " --ch R=cloud.R,G=cloud.G,B=cloud.B,A=cloud.A " + frame +
                                      " --ch R=surfaces.R,G=surfaces.G,B=surfaces.B,A=surfaces.A --over -o " + over +
                                      " && oiiotool " + frame + " --ch R,G,B,A -o " + beauty + " && idiff -q -fail 1e-4 " + over +
                                      " " + beauty;
        CHECK(std::system(composite.c_str()) == 0);
    }
}

TEST_CASE("render passes: each pixel names the nearest object, its normal and the cloud's shadow on it", "[render]")
{
    SmallScene scene;
    scene.frame.passes = true;
    scene.settings.sun.direction = Vec3d(0, 1, 0);
    // Over the ground left of the pillar: its shadow falls straight down.
    const LitCloud cloud(constantBox({-18, 3, -3}, {-8, 4, 3}, 0.25, 2.0f), scene.settings, scene.settings.sun.direction,
                         &scene.surfaces);
    scene.frame.volume = &cloud.volume;
    const RenderImage image = renderFrame(scene.frame);
    const RenderPasses& passes = image.passes;
    const auto at = [&](const std::vector<float>& pass, int channels, const Vec3d& world, int channel = 0) {
        const Vec2d pixel = *scene.frame.camera.imagePoint(world);
        return pass[std::size_t(channels) * (std::size_t(pixel[1]) * image.width + std::size_t(pixel[0])) + channel];
    };
    // The pillar (object 1) in front, the ground (object 0) around it, the sky above.
    CHECK(at(passes.objectIndex, 1, {0, 3, 2}) == 2.0f);
    CHECK(at(passes.objectIndex, 1, {10, 0, 5}) == 1.0f);
    CHECK(passes.objectIndex[0] == 0.0f);
    // The pillar's front face looks at +z; the ground up.
    CHECK(at(passes.normal, 3, {0, 3, 2}, 2) == Approx(1.0).margin(0.05));
    CHECK(at(passes.normal, 3, {10, 0, 5}, 1) == Approx(1.0).margin(0.05));
    // Under the cloud the ground is in its shadow (an optical depth of about
    // 2: most of the sun is taken); beside it, none.
    CHECK(at(passes.shadow, 1, {-13, 0, 0}) > 0.3f);
    CHECK(at(passes.shadow, 1, {10, 0, 5}) == 0.0f);
    CHECK(passes.shadow[0] == 0.0f);
    // The EXR names the layers as Nuke and Blender do, and the objects in its header.
    const std::string path = test::scratchDir("render-passes-names") + "/frame.exr";
    RenderImage named = image;
    named.passes.objectNames = {"ground", "pillar"};
    writeFrameImage(named, path, DisplayView(scene.settings.view));
    OIIO::ImageBuf exr(path);
    REQUIRE(exr.read());
    std::vector<std::string> channels = exr.spec().channelnames;
    std::sort(channels.begin(), channels.end());
    CHECK(channels == std::vector<std::string>{
                          "A",          "B",          "G",          "R",          "Z",        "cloud.A",       "cloud.B",
                          "cloud.G",    "cloud.R",    "normal.X",   "normal.Y",   "normal.Z", "objectIndex.X", "shadow.X",
                          "surfaces.A", "surfaces.B", "surfaces.G", "surfaces.R", "vector.W", "vector.X",      "vector.Y",
                          "vector.Z"});
    CHECK(exr.spec().get_string_attribute("vfield:objectIndex") == R"({"1":"ground","2":"pillar"})");
}

TEST_CASE("render passes: motion vectors are what a pixel sees moving on the screen, from the previous frame and to the next",
          "[render]")
{
    // A box crossing the view at 1 unit a frame, 28 units in front of a
    // camera looking straight at it; the ground stands still.
    RenderSettings settings;
    settings.camera.position = Vec3d(0, 3, 30);
    settings.camera.lookAt = Vec3d(0, 3, 0);
    settings.image.width = 96;
    settings.image.height = 54;
    settings.image.samplesPerPixel = 1; // through each pixel's centre
    SurfaceScene surfaces;
    surfaces.addStatic(0, makeBox({{-40, -2, -40}, {40, 0, 40}}), Transform{});
    surfaces.addDynamic(1, makeBox({{-2, 1, -2}, {2, 5, 2}}));
    surfaces.setPose(1, Transform{});
    surfaces.commit();
    const Camera camera = Camera::fromSettings(settings.camera, settings.image.width, settings.image.height);
    const auto movedBy = [](double x) {
        Transform pose;
        pose.translation = Vec3d(x, 0, 0);
        return pose;
    };
    FrameToRender frame;
    frame.settings = &settings;
    frame.surfaces = &surfaces;
    frame.camera = camera;
    frame.passes = true;
    const auto vectorAt = [&](const RenderImage& image, const Vec3d& world) {
        const Vec2d pixel = *camera.imagePoint(world);
        const float* v = &image.passes.vector[4 * (std::size_t(pixel[1]) * image.width + std::size_t(pixel[0]))];
        return Vec4d(v[0], v[1], v[2], v[3]);
    };
    const Vec3d boxFront(0, 3, 2), ground(8, 0, 10), sky = camera.position() + camera.direction(2, 2) * 1000.0;
    // focal length in pixels over the depth: one unit across at depth 28.
    const double pixelsPerUnit = 27.0 / std::tan(22.5 * M_PI / 180.0) / 28.0;

    SECTION("a moving object, a still camera")
    {
        const ScreenMotion motion({camera, {{1, movedBy(-1)}}}, {camera, {{1, movedBy(0)}}}, {camera, {{1, movedBy(1)}}});
        frame.screenMotion = &motion;
        for (const IntegratorKind kind : {IntegratorKind::Fast, IntegratorKind::Reference}) {
            INFO(enumName(kind));
            settings.integrator.kind = kind;
            const RenderImage image = renderFrame(frame);
            const Vec4d box = vectorAt(image, boxFront);
            CHECK(box[0] == Approx(pixelsPerUnit).epsilon(1e-3));
            CHECK(box[1] == Approx(0.0).margin(1e-4));
            CHECK(box[2] == Approx(pixelsPerUnit).epsilon(1e-3));
            CHECK(box[3] == Approx(0.0).margin(1e-4));
            CHECK(vectorAt(image, ground) == Vec4d(0.0));
            CHECK(vectorAt(image, sky) == Vec4d(0.0));
        }
    }
    SECTION("a camera rising and turning: the ground moves down, the sky with the turn alone")
    {
        CameraSettings before = settings.camera, after = settings.camera;
        before.position[1] -= 1;
        before.lookAt[1] -= 1;
        after.lookAt = Vec3d(30, 3, 0); // an eighth of a turn to the right
        const Camera previous = Camera::fromSettings(before, settings.image.width, settings.image.height);
        const Camera next = Camera::fromSettings(after, settings.image.width, settings.image.height);
        const ScreenMotion motion({previous, {}}, {camera, {}}, {next, {}});
        frame.screenMotion = &motion;
        const RenderImage image = renderFrame(frame);
        // Risen by a unit, the camera sees the ground one unit's worth lower
        // (y up: negative), at the depth seen through the pixel.
        const Vec2d groundPixel = *camera.imagePoint(ground);
        const Vec3d centre = camera.direction(std::floor(groundPixel[0]) + 0.5, std::floor(groundPixel[1]) + 0.5);
        const double groundDepth = -camera.position()[1] / centre[1] * centre.dot(camera.forward());
        CHECK(vectorAt(image, ground)[1] == Approx(-pixelsPerUnit * 28.0 / groundDepth).epsilon(1e-3));
        CHECK(vectorAt(image, ground)[0] == Approx(0.0).margin(0.05));
        // The sky does not move with the camera's rise, and moves left as it turns right.
        const Vec4d skyMotion = vectorAt(image, sky);
        CHECK(skyMotion[0] == Approx(0.0).margin(1e-6));
        CHECK(skyMotion[1] == Approx(0.0).margin(1e-6));
        CHECK(skyMotion[2] < -10.0);
    }
}

TEST_CASE("render passes: the beauty is the same with and without them, bit for bit", "[render]")
{
    SmallScene scene;
    const LitCloud cloud(constantBox({-6, 2, -3}, {6, 6, 3}, 0.25, 0.6f), scene.settings, scene.settings.sun.direction,
                         &scene.surfaces);
    scene.frame.volume = &cloud.volume;
    for (const IntegratorKind kind : {IntegratorKind::Fast, IntegratorKind::Reference}) {
        scene.settings.integrator.kind = kind;
        scene.frame.passes = true;
        const RenderImage with = renderFrame(scene.frame);
        scene.frame.passes = false;
        const RenderImage without = renderFrame(scene.frame);
        CHECK(without.passes.empty());
        CHECK_FALSE(with.passes.empty());
        CHECK(with.rgba == without.rgba);
        CHECK(with.depth == without.depth);
    }
}

TEST_CASE("render: EXR frames composite over a plate with OIIO's over", "[render]")
{
    // Premultiplied RGBA: a drawn sky is opaque and hides the plate; a
    // transparent sky shows it, and thin cloud adds its light over it.
    SmallScene scene;
    scene.settings.image.samplesPerPixel = 1;
    const LitCloud cloud(constantBox({-6, 8, -3}, {6, 11, 3}, 0.25, 0.3f), scene.settings, scene.settings.sun.direction,
                         &scene.surfaces);
    scene.frame.volume = &cloud.volume;
    const std::string dir = test::scratchDir("render-over");
    const auto rgbaOf = [&](bool transparentSky) {
        scene.settings.image.transparentSky = transparentSky;
        const std::string path = dir + (transparentSky ? "/transparent.exr" : "/drawn.exr");
        writeFrameImage(renderFrame(scene.frame), path, DisplayView(scene.settings.view));
        OIIO::ImageBuf exr(path);
        REQUIRE(exr.read(0, 0, true, OIIO::TypeDesc::FLOAT));
        return OIIO::ImageBufAlgo::channels(exr, 4, {0, 1, 2, 3});
    };
    const OIIO::ImageBuf drawn = rgbaOf(false), transparent = rgbaOf(true);
    OIIO::ImageBuf plate(drawn.spec());
    const float red[4] = {0.8f, 0.1f, 0.1f, 1.0f};
    OIIO::ImageBufAlgo::fill(plate, red);
    const OIIO::ImageBuf overDrawn = OIIO::ImageBufAlgo::over(drawn, plate);
    const OIIO::ImageBuf overTransparent = OIIO::ImageBufAlgo::over(transparent, plate);

    int skyPixels = 0, cloudPixels = 0;
    for (int y = 0; y < drawn.spec().height; ++y)
        for (int x = 0; x < drawn.spec().width; ++x) {
            float d[4], t[4], od[4], ot[4];
            drawn.getpixel(x, y, d, 4);
            transparent.getpixel(x, y, t, 4);
            overDrawn.getpixel(x, y, od, 4);
            overTransparent.getpixel(x, y, ot, 4);
            INFO("pixel " << x << ", " << y);
            REQUIRE(d[3] == 1.0f);
            for (int c = 0; c < 3; ++c) REQUIRE(od[c] == Approx(d[c]).margin(1e-6)); // the plate is hidden
            for (int c = 0; c < 3; ++c) REQUIRE(ot[c] == Approx(t[c] + red[c] * (1.0f - t[3])).margin(2e-3));
            if (t[3] == 0.0f) {
                ++skyPixels;
                for (int c = 0; c < 3; ++c) REQUIRE(t[c] == 0.0f); // nothing added where nothing covers
            } else if (t[3] < 0.999f) {
                ++cloudPixels;
            }
        }
    CHECK(skyPixels > 100);
    CHECK(cloudPixels > 100);
}

TEST_CASE("render: terrain noise gains detail only where a pixel resolves it, fading in without a jump", "[render]")
{
    const SurfaceMaterial rock = SurfaceMaterial::terrain();
    const Vec3d p(12.3, 4.5, -6.7);
    const SurfaceNoise coarse = surfaceNoise(rock, p); // no footprint given: nothing finer than 0.75 units
    CHECK(coarse.detail == 0.0);
    // The first detail octave (period 0.375) starts where a pixel is half of it wide.
    const SurfaceNoise atLimit = surfaceNoise(rock, p, 0.1875);
    CHECK(atLimit.detail == 0.0);
    CHECK(atLimit.bumpGradient == coarse.bumpGradient);
    const SurfaceNoise justBelow = surfaceNoise(rock, p, 0.1875 * 0.999);
    CHECK(std::abs(justBelow.detail) < 1e-3);
    CHECK((justBelow.bumpGradient - coarse.bumpGradient).length() < 1e-3);
    // Beside the camera (a pixel of 1 mm) every octave is drawn and changes both.
    double detailSeen = 0.0, tiltSeen = 0.0;
    for (int i = 0; i < 16; ++i) {
        const Vec3d q = p + Vec3d(0.31 * i, 0.17 * i, -0.05 * i);
        const SurfaceNoise fine = surfaceNoise(rock, q, 0.001);
        detailSeen = std::max(detailSeen, std::abs(fine.detail));
        tiltSeen = std::max(tiltSeen, (fine.bumpGradient - surfaceNoise(rock, q).bumpGradient).length());
        CHECK(std::abs(fine.detail) <= 1.0);
    }
    CHECK(detailSeen > 0.1);
    CHECK(tiltSeen > 0.1);
    // Painted surfaces stay plain however close.
    CHECK(surfaceNoise(SurfaceMaterial::painted(Vec3d(1.0)), p, 0.001).detail == 0.0);
}

TEST_CASE("render: skipping empty space leaves every sample of the march where it was", "[render]")
{
    // Two clouds along the ray with empty nodes between: the skipper marches
    // them as separate spans, and must sample the same depths as a march
    // through the whole box (restarted at each span, its steps showed as
    // stripes along node boundaries).
    openvdb::FloatGrid::Ptr grid = constantBox({-40, -3, -3}, {-25, 3, 3}, 0.25, 0.7f);
    openvdb::tools::compMax(*grid, *constantBox({22.3, -3, -3}, {40, 3, 3}, 0.25, 0.4f));
    RenderSettings skipping = medium(0.5, 0.9, 0.3, 0.5), marching = skipping;
    skipping.integrator.skipEmptySpace = true;
    marching.integrator.skipEmptySpace = false;
    const LitCloud skipped(grid, skipping, Vec3d(0, 1, 0), nullptr), whole(grid, marching, Vec3d(0, 1, 0), nullptr);
    for (const double jitter : {0.1, 0.5, 0.93})
        for (const double y : {-2.0, 0.3, 1.7}) {
            const Vec3d origin(-60, y, 0.1), dir = Vec3d(1, 0.01, 0.02).unit();
            const CloudVolume::Segment a = skipped.volume.march(origin, dir, 0.0, 1e9, jitter, Vec3d(2.0), Vec3d(0.5));
            const CloudVolume::Segment b = whole.volume.march(origin, dir, 0.0, 1e9, jitter, Vec3d(2.0), Vec3d(0.5));
            INFO("jitter " << jitter << ", y " << y);
            CHECK(a.transmittance < 0.99);
            CHECK(a.transmittance == Approx(b.transmittance).epsilon(1e-9));
            CHECK(a.radiance[0] == Approx(b.radiance[0]).epsilon(1e-9));
            CHECK(a.distance == Approx(b.distance).epsilon(1e-9));
        }
}

TEST_CASE("render: skipping empty space keeps the reads that reach a leaf's corner diagonally", "[render]")
{
    // One voxel at a leaf's first corner: a trilinear read whose cell starts a
    // voxel before it along all three axes, in the leaf diagonally behind,
    // reads it. That leaf holds no voxel of the density, nor of its dilation
    // across faces, which is all OpenVDB's intersector dilates.
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    grid->tree().setValue(openvdb::Coord(8, 8, 8), 5.0f);
    RenderSettings skipping = medium(0.5, 0.9, 0.3, 0.25), marching = skipping;
    skipping.integrator.skipEmptySpace = true;
    marching.integrator.skipEmptySpace = false;
    const LitCloud skipped(grid, skipping, Vec3d(0, 1, 0), nullptr), whole(grid, marching, Vec3d(0, 1, 0), nullptr);
    const Vec3d origin(-20, 7.5, 7.5), dir(1, 0, 0); // through cells (7, 7, 7) and (8, 7, 7), in leaves (0, 0, 0) and (8, 0, 0)
    const CloudVolume::Segment a = skipped.volume.march(origin, dir, 0.0, 1e9, 0.5, Vec3d(2.0), Vec3d(0.5));
    const CloudVolume::Segment b = whole.volume.march(origin, dir, 0.0, 1e9, 0.5, Vec3d(2.0), Vec3d(0.5));
    CHECK(b.transmittance < 0.99);
    CHECK(a.transmittance == Approx(b.transmittance).epsilon(1e-9));
    CHECK(a.radiance[0] == Approx(b.radiance[0]).epsilon(1e-9));
}
