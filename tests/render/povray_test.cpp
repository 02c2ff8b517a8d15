// The POV-Ray back-end: df3 export, the written scene text, and POV-Ray's
// picture against vfield's own.

#include "test_meshes.h"

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>
#include <vfield/core/image_file.h>
#include <vfield/mesh/procedural.h>
#include <vfield/render/embree/cloud_volume.h>
#include <vfield/render/embree/embree_backend.h>
#include <vfield/render/embree/renderer.h>
#include <vfield/render/embree/surfaces.h>
#include <vfield/render/frame_image.h>
#include <vfield/render/povray/df3.h>
#include <vfield/render/povray/povray_backend.h>
#include <vfield/render/povray/povray_runner.h>
#include <vfield/render/povray/povray_scene.h>

#include <catch2/catch.hpp>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>

using namespace vfield;
namespace fs = std::filesystem;

namespace {

/// Compares text with a checked-in file; on a difference, writes the new text
/// beside the build so a reviewer can diff it and copy it over on purpose.
void checkMatchesExpected(const std::string& text, const std::string& expectedName)
{
    const std::string expectedPath = test::dataPath("povray/" + expectedName);
    const std::string actualPath = fs::absolute(fs::path("povray-actual") / expectedName).string();
    if (text == test::readTextFile(expectedPath)) return;
    writeTextAtomically(actualPath, text);
    FAIL("the exported text differs from " << expectedPath << "; the new text is in " << actualPath);
}

/// The small fixed scene: a ground slab and a pillar (static), a box in flight
/// (dynamic) and a 2 x 2 x 1 voxel cloud.
struct FixedScene {
    TriangleMesh ground = makeBox({{-10, -1, -10}, {10, 0, 10}});
    TriangleMesh pillar = makeBox({{-1, 0, -1}, {1, 4, 1}});
    TriangleMesh flyer = makeBox({{-0.5, -0.25, -0.5}, {0.5, 0.25, 0.5}});
    RenderSettings settings;
    openvdb::FloatGrid::Ptr cloud;

    FixedScene()
    {
        settings.camera.position = Vec3d(0, 6, 25);
        settings.camera.lookAt = Vec3d(0, 2, 0);
        settings.integrator.volumeStep = 0.25;
        openvdb::initialize();
        cloud = openvdb::FloatGrid::create(0.0f);
        cloud->setTransform(openvdb::math::Transform::createLinearTransform(1.0));
        auto accessor = cloud->getAccessor();
        accessor.setValue(openvdb::Coord(2, 5, 0), 1.0f);
        accessor.setValue(openvdb::Coord(3, 5, 0), 0.5f);
        accessor.setValue(openvdb::Coord(2, 6, 0), 0.25f);
        accessor.setValue(openvdb::Coord(3, 6, 0), 2.0f);
    }

    std::string meshesText() const
    {
        std::vector<PovrayMesh> meshes(3);
        meshes[0] = {0, &ground, SurfaceMaterial::terrain(), Transform{}};
        meshes[1] = {1, &pillar, SurfaceMaterial{}, Transform{}};
        meshes[2] = {2, &flyer, SurfaceMaterial{}, std::nullopt};
        return povrayMeshesText(meshes, -1.0, 4.0);
    }

    std::string frameText(const std::string& folder) const
    {
        PovrayFrame frame;
        frame.settings = &settings;
        frame.camera = Camera::fromSettings(settings.camera, 64, 36);
        frame.frame = 12;
        frame.meshInclude = "meshes.inc";
        frame.staticObjects = {0, 1};
        Transform pose;
        pose.translation = Vec3d(-4, 3, 2);
        pose.rotation = Transform::rotationFromDegrees(Vec3d(10, 30, 0));
        pose.scale = 2.0;
        frame.dynamicPoses[2] = pose;
        PovrayCloud povCloud;
        povCloud.df3File = "density.0012.df3";
        povCloud.placement = writeDf3(*cloud, folder + "/density.0012.df3");
        povCloud.skyLitDf3File = "sky_lit.0012.df3";
        povCloud.skyLitPlacement = writeDf3(*cloud, folder + "/sky_lit.0012.df3");
        frame.cloud = povCloud;
        return povrayFrameText(frame);
    }
};

/// A density grid alone in the sky, drawn by both back-ends: linear RGB
/// images, from PNG frames shown through the Standard view (sRGB, clipped at 1).
struct CloudInBoth {
    OIIO::ImageBuf embree, povray;
};

CloudInBoth renderCloudInBoth(const openvdb::FloatGrid::Ptr& density, RenderSettings settings, const std::string& dir,
                              const PovraySettings& povraySettings = {})
{
    settings.view.view = "Standard";
    SurfaceScene nothing;
    nothing.commit();
    const CloudLighting lighting(density, settings.medium, settings.sun.direction, {});
    FrameView view;
    view.frame = 1;
    view.settings = &settings;
    view.camera = Camera::fromSettings(settings.camera, settings.image.width, settings.image.height);
    view.cloud = &lighting;
    EmbreeBackend embree(settings, nothing, {}, 0.0, 1.0, {"png"}, {});
    PovrayBackend povray({}, 0.0, 1.0, settings, povraySettings, dir + "/povray-scene", 2);
    for (RenderBackend* backend : {static_cast<RenderBackend*>(&embree), static_cast<RenderBackend*>(&povray)}) {
        backend->prepare();
        backend->render(view, dir + "/" + backend->name());
    }

    CloudInBoth images;
    for (auto [name, image] : {std::pair{"embree", &images.embree}, std::pair{"povray", &images.povray}}) {
        OIIO::ImageBuf srgb(dir + "/" + name + "/frame.0001.png");
        REQUIRE(srgb.read(0, 0, true, OIIO::TypeDesc::FLOAT));
        *image = OIIO::ImageBufAlgo::colorconvert(srgb, "sRGB", "linear");
    }
    return images;
}

/// Mean luminance-like sum of RGB over a pixel window.
double meanRgb(const OIIO::ImageBuf& image, const OIIO::ROI& window)
{
    double sum = 0.0;
    for (int y = window.ybegin; y < window.yend; ++y)
        for (int x = window.xbegin; x < window.xend; ++x) {
            float rgb[3];
            image.getpixel(x, y, rgb, 3);
            sum += rgb[0] + rgb[1] + rgb[2];
        }
    return sum / double(window.npixels());
}

/// Sets PATH for the scope of the object.
class ScopedPath {
public:
    explicit ScopedPath(const std::string& path) : mOld(std::getenv("PATH") ? std::getenv("PATH") : "")
    {
        ::setenv("PATH", path.c_str(), 1);
    }
    ~ScopedPath() { ::setenv("PATH", mOld.c_str(), 1); }

private:
    std::string mOld;
};

} // namespace

TEST_CASE("povray: the exported scene text equals the checked-in files", "[povray]")
{
    const FixedScene scene;
    const std::string dir = test::scratchDir("povray-text");
    checkMatchesExpected(scene.meshesText(), "meshes.inc");
    checkMatchesExpected(scene.frameText(dir), "frame.0012.pov");
}

TEST_CASE("povray: POV-Ray renders the exported scene", "[povray]")
{
    // POV-Ray is a dependency tools/setup installs: without it this test fails, naming the package.
    REQUIRE_NOTHROW(requirePovray());
    const FixedScene scene;
    const std::string dir = test::scratchDir("povray-run");
    writeTextAtomically(dir + "/meshes.inc", scene.meshesText());
    writeTextAtomically(dir + "/frame.0012.pov", scene.frameText(dir));
    ImageSettings size;
    size.width = 64;
    size.height = 36;
    size.samplesPerPixel = 1;
    runPovray(dir, "frame.0012.pov", "render.exr", size, PovrayQuality::Final, 1);
    OIIO::ImageBuf image(dir + "/render.exr");
    REQUIRE(image.read(0, 0, true, OIIO::TypeDesc::FLOAT));
    CHECK(image.spec().width == 64);
    CHECK(image.spec().height == 36);
    // Blue sky at the top, green ground in front of the pillar.
    float top[3], ground[3];
    image.getpixel(32, 1, top, 3);
    image.getpixel(20, 25, ground, 3);
    CHECK(top[2] > top[0]);
    CHECK(ground[1] > ground[2]);
    CHECK(ground[1] > ground[0]);
}

TEST_CASE("povray: terrain against the sky agrees with vfield's renderer (IoU >= 0.98)", "[povray]")
{
    // POV-Ray is a dependency tools/setup installs: without it this test fails, naming the package.
    REQUIRE_NOTHROW(requirePovray());
    TerrainSettings terrain;
    terrain.sizeX = terrain.sizeZ = 100.0;
    terrain.cellsX = terrain.cellsZ = 64;
    terrain.amplitude = 25.0;
    const TriangleMesh mesh = makeTerrain(terrain);

    // A pure blue sky: sunlit terrain has red in it, and the sides the sun
    // misses get at most half the sky's blue, so anything not pure blue is terrain.
    RenderSettings settings;
    settings.sky.zenithColor = settings.sky.horizonColor = Vec3d(0, 0, 1);
    settings.sun.direction = Vec3d(0.05, 1.0, 0.02);
    settings.camera.position = Vec3d(-80, 30, 60);
    settings.camera.lookAt = Vec3d(0, 12, 0);
    const int width = 160, height = 90;
    settings.image.width = width;
    settings.image.height = height;
    settings.image.samplesPerPixel = 1;

    SurfaceScene surfaces;
    surfaces.addStatic(0, mesh, Transform{});
    surfaces.commit();
    FrameToRender embree;
    embree.settings = &settings;
    embree.surfaces = &surfaces;
    embree.materials[0] = SurfaceMaterial::terrain();
    embree.camera = Camera::fromSettings(settings.camera, width, height);
    embree.terrainLow = mesh.bounds().min()[1];
    embree.terrainHigh = mesh.bounds().max()[1];
    const std::string dir = test::scratchDir("povray-mask");
    // Both through the Standard view: pure blue stays pure blue.
    const DisplayView standard(ViewSettings{"Standard", 0.0});
    writeFrameImage(renderFrame(embree), dir + "/vfield.png", standard);
    writeTextAtomically(dir + "/meshes.inc", povrayMeshesText({{0, &mesh, SurfaceMaterial::terrain(), Transform{}}},
                                                              mesh.bounds().min()[1], mesh.bounds().max()[1]));
    PovrayFrame frame;
    frame.settings = &settings;
    frame.camera = embree.camera;
    frame.meshInclude = "meshes.inc";
    frame.staticObjects = {0};
    writeTextAtomically(dir + "/terrain.pov", povrayFrameText(frame));
    runPovray(dir, "terrain.pov", "terrain.exr", settings.image, PovrayQuality::Final, 1);
    OIIO::ImageBuf ours(dir + "/vfield.png");
    REQUIRE(ours.read(0, 0, true, OIIO::TypeDesc::FLOAT));
    const OIIO::ImageBuf theirs = toDisplay(readImageAsFloat(dir + "/terrain.exr"), standard);
    const auto isTerrain = [](const OIIO::ImageBuf& image, int x, int y) {
        float rgb[3];
        image.getpixel(x, y, rgb, 3);
        return rgb[0] + rgb[1] + (1.0f - rgb[2]) > 0.1f;
    };

    int both = 0, either = 0, skyInOurs = 0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const bool povTerrain = isTerrain(theirs, x, y), ourTerrain = isTerrain(ours, x, y);
            both += povTerrain && ourTerrain;
            either += povTerrain || ourTerrain;
            skyInOurs += !ourTerrain;
        }
    const double iou = double(both) / double(either);
    INFO("terrain masks: IoU " << iou << " (" << either - both << " of " << width * height << " pixels differ)");
    REQUIRE(skyInOurs > width * height / 10); // the frame shows the silhouette against the sky
    CHECK(iou >= 0.98);
}

TEST_CASE("povray: a missing povray names the package, and a failing scene carries its log", "[povray]")
{
    const std::string dir = test::scratchDir("povray-errors");
    writeTextAtomically(dir + "/broken.pov", "#version 3.7;\nbox { <0, 0, 0>, <1, 1, 1>\n");
    {
        const ScopedPath nowhere(dir + "/no-such-folder");
        CHECK_FALSE(povrayAvailable());
        CHECK_THROWS_WITH(runPovray(dir, "broken.pov", "out.exr", ImageSettings{}, PovrayQuality::Final, 1),
                          "POV-Ray (the povray program) is not on PATH; install the Debian package 'povray' "
                          "(tools/setup does)");
    }
    // POV-Ray is a dependency tools/setup installs: without it this test fails, naming the package.
    REQUIRE_NOTHROW(requirePovray());
    try {
        runPovray(dir, "broken.pov", "out.exr", ImageSettings{}, PovrayQuality::Final, 1);
        FAIL("a broken scene rendered");
    } catch (const FileError& e) {
        const std::string message = e.what();
        CHECK(message.rfind(dir + "/broken.pov: POV-Ray failed (exit status 1): ", 0) == 0);
        CHECK(message.find("Parse Error") != std::string::npos);
        CHECK(message.find("(log: " + dir + "/out.exr.log)") != std::string::npos);
        CHECK(message.find('\n') == std::string::npos);
    }
    CHECK_FALSE(fs::exists(dir + "/out.exr"));
}

TEST_CASE("povray: the fraction of pixels POV-Ray reports rendered is told while it renders, never shrinking", "[povray]")
{
    const std::string dir = test::scratchDir("povray-progress");
    // A sphere supersampled 9 x 9 on one thread: about a second and a half.
    writeTextAtomically(dir + "/sphere.pov", "#version 3.7;\ncamera { location <0, 0, -5> look_at 0 }\n"
                                             "light_source { <10, 10, -10> color rgb 1 }\n"
                                             "sphere { 0, 1 pigment { color rgb 1 } }\n");
    ImageSettings image;
    image.width = 320;
    image.height = 240;
    image.samplesPerPixel = 81;
    std::vector<double> told;
    runPovray(dir, "sphere.pov", "sphere.exr", image, PovrayQuality::Final, 1,
              [&](double fraction) { told.push_back(fraction); });
    REQUIRE_FALSE(told.empty());
    CHECK(std::is_sorted(told.begin(), told.end()));
    CHECK(told.front() >= 0.0);
    CHECK(told.back() > 0.0);
    CHECK(told.back() <= 1.0);
}

TEST_CASE("povray: a forward-scattering box agrees with vfield's within 10%, towards and away from the sun", "[povray]")
{
    // POV-Ray averages the phase functions of all media a ray is in: with the
    // sky light's isotropic medium beside the cloud's, anisotropy 0.6 scattered
    // (HG + 1) / 2, half the forward lobe and 3.7 times the backward one.
    REQUIRE_NOTHROW(requirePovray());
    openvdb::initialize();
    const openvdb::FloatGrid::Ptr box = openvdb::FloatGrid::create(0.0f);
    box->setTransform(openvdb::math::Transform::createLinearTransform(0.25));
    box->fill(openvdb::CoordBBox(openvdb::Coord(-16), openvdb::Coord(15)), 1.0f); // 8 units a side
    RenderSettings settings;
    settings.medium = {0.2, 0.9, 0.6};
    settings.sun.direction = Vec3d(1, 0.25, 0).unit();
    settings.sky.intensity = 0.3;
    settings.image.width = 96;
    settings.image.height = 64;
    settings.image.samplesPerPixel = 4;
    settings.integrator.volumeStep = 0.25;              // POV-Ray's cost grows as its square (media and light samples)
    settings.integrator.multipleScattering.octaves = 1; // POV-Ray's media scatter once
    const OIIO::ROI centre(40, 56, 24, 40, 0, 1, 0, 3); // inside the box's silhouette from both sides
    // 30 degrees off the sun: vfield's sky draws the sun's glow and disk, which
    // POV-Ray's light does not, and straight at the sun they shine through the box.
    const double turn = 30.0 * M_PI / 180.0;
    const Vec3d& s = settings.sun.direction;
    const Vec3d view = Vec3d(s[0] * std::cos(turn) - s[2] * std::sin(turn), s[1], s[0] * std::sin(turn) + s[2] * std::cos(turn));
    for (const double side : {1.0, -1.0}) {
        // side 1: the camera looks through the box towards the sun; -1: away from it.
        settings.camera.position = -view * (side * 20.0);
        settings.camera.lookAt = Vec3d(0.0);
        settings.camera.fovDegrees = 40;
        const CloudInBoth images =
            renderCloudInBoth(box, settings, test::scratchDir(side > 0 ? "povray-phase-towards" : "povray-phase-away"));
        const double ours = meanRgb(images.embree, centre), theirs = meanRgb(images.povray, centre);
        INFO((side > 0 ? "towards" : "away from")
             << " the sun: vfield " << ours << ", POV-Ray " << theirs << " (ratio " << theirs / ours << ")");
        // With the phases averaged unbent, the ratios stray far both ways;
        // bent, about 1.005 towards and 0.93 away (the rest away from the sun is
        // POV-Ray's sky light, an emission of the sky's mean colour:
        // docs/rendering.md, "POV-Ray").
        CHECK(theirs == Approx(ours).epsilon(0.10));
    }
}

TEST_CASE("povray: preview quality gives the final image's cloud within 3%", "[povray]")
{
    // Preview antialiases only pixels that stand out and takes a quarter of
    // the media samples (docs/rendering.md, "POV-Ray").
    REQUIRE_NOTHROW(requirePovray());
    openvdb::initialize();
    const openvdb::FloatGrid::Ptr box = openvdb::FloatGrid::create(0.0f);
    box->setTransform(openvdb::math::Transform::createLinearTransform(0.25));
    box->fill(openvdb::CoordBBox(openvdb::Coord(-16), openvdb::Coord(15)), 1.0f);
    RenderSettings settings;
    settings.medium = {0.2, 0.9, 0.6};
    // Small, since final quality supersamples every pixel through 139 media
    // samples: a larger image would come near ctest's time limit under load.
    settings.image.width = 48;
    settings.image.height = 32;
    settings.image.samplesPerPixel = 9;
    settings.integrator.volumeStep = 0.1;
    settings.camera.position = Vec3d(-14, 6, 14);
    settings.camera.lookAt = Vec3d(0.0);
    settings.camera.fovDegrees = 40;
    const OIIO::ROI centre(20, 28, 12, 20, 0, 1, 0, 3);
    const double final = meanRgb(renderCloudInBoth(box, settings, test::scratchDir("povray-final")).povray, centre);
    PovraySettings previewQuality;
    previewQuality.quality = PovrayQuality::Preview;
    const double preview =
        meanRgb(renderCloudInBoth(box, settings, test::scratchDir("povray-preview"), previewQuality).povray, centre);
    INFO("final " << final << ", preview " << preview);
    CHECK(preview == Approx(final).epsilon(0.03));
}

TEST_CASE("povray: a one-voxel density impulse lands on the same pixel in both back-ends", "[povray]")
{
    // df3 samples sit at i/n of POV-Ray's cube; placed at cell centres, the
    // cloud moved by half a cell.
    REQUIRE_NOTHROW(requirePovray());
    openvdb::initialize();
    const openvdb::FloatGrid::Ptr impulse = openvdb::FloatGrid::create(0.0f);
    impulse->setTransform(openvdb::math::Transform::createLinearTransform(1.0));
    impulse->tree().setValue(openvdb::Coord(3, 2, -1), 40.0f);
    const openvdb::FloatGrid::Ptr empty = openvdb::FloatGrid::create(0.0f);
    RenderSettings settings;
    settings.medium = {1.0, 0.0, 0.0}; // absorbing: a dark spot against the sky
    settings.sky.zenithColor = settings.sky.horizonColor = Vec3d(0.6, 0.7, 0.9);
    settings.image.width = 64;
    settings.image.height = 64;
    settings.image.samplesPerPixel = 4;
    settings.integrator.volumeStep = 0.05;
    settings.camera.position = Vec3d(1, 1, 12); // off-axis, so a shift on any axis moves the spot
    settings.camera.lookAt = Vec3d(3, 2, -1);
    settings.camera.fovDegrees = 20;
    const CloudInBoth with = renderCloudInBoth(impulse, settings, test::scratchDir("povray-impulse"));
    const CloudInBoth without = renderCloudInBoth(empty, settings, test::scratchDir("povray-impulse-sky"));
    // The spot's centre: pixels weighted by how much sky the impulse took away.
    const auto spot = [&](const OIIO::ImageBuf& image, const OIIO::ImageBuf& sky) {
        double sum = 0.0, x = 0.0, y = 0.0;
        for (int py = 0; py < settings.image.height; ++py)
            for (int px = 0; px < settings.image.width; ++px) {
                float a[3], b[3];
                image.getpixel(px, py, a, 3);
                sky.getpixel(px, py, b, 3);
                const double w = std::max(0.0, double(b[0] + b[1] + b[2] - a[0] - a[1] - a[2]));
                sum += w;
                x += w * (px + 0.5);
                y += w * (py + 0.5);
            }
        REQUIRE(sum > 0.0);
        return std::pair{x / sum, y / sum};
    };
    const auto [ox, oy] = spot(with.embree, without.embree);
    const auto [px, py] = spot(with.povray, without.povray);
    INFO("impulse centre: vfield (" << ox << ", " << oy << "), POV-Ray (" << px << ", " << py << ") pixels; a voxel spans about "
                                    << settings.image.height / (2 * 13 * std::tan(10 * M_PI / 180)) << " pixels");
    CHECK(std::hypot(px - ox, py - oy) < 0.5);
}
