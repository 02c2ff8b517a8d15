// Motion blur against time: a frame rendered with its shutter open is the
// mean of renders at instants spread over the shutter, for a cloud moving by
// its velocity grid and for a moving object, with either integrator; and the
// fast integrator's paths gathered over frames, moved by the cloud's velocity.

#include <vfield/folder/tracks.h>
#include <vfield/mesh/procedural.h>
#include <vfield/render/cloud_motion.h>
#include <vfield/render/embree/renderer.h>
#include <vfield/render/embree/scattered_light.h>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace vfield;

namespace {

constexpr double kSecondsPerFrame = 1.0 / 24.0;
constexpr double kOpen = -0.25, kClose = 0.25; ///< Blender's shutter of 0.5
constexpr int kInstants = 32;

/// A ball of cloud, denser towards its centre, and a `vel` grid of one
/// velocity over its voxels.
struct MovingBall {
    openvdb::FloatGrid::Ptr density;
    openvdb::Vec3SGrid::Ptr velocity;

    MovingBall(const Vec3d& centre, double radius, double voxel, const Vec3d& speed)
    {
        openvdb::initialize();
        density = openvdb::FloatGrid::create(0.0f);
        velocity = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
        density->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
        velocity->setTransform(density->transform().copy());
        auto rho = density->getAccessor();
        auto vel = velocity->getAccessor();
        const int n = int(std::ceil(radius / voxel));
        const openvdb::Coord c = openvdb::Coord::round(centre / voxel);
        for (int i = -n; i <= n; ++i)
            for (int j = -n; j <= n; ++j)
                for (int k = -n; k <= n; ++k) {
                    const openvdb::Coord ijk = c.offsetBy(i, j, k);
                    const double r = (density->indexToWorld(ijk) - centre).length() / radius;
                    if (r >= 1.0) continue;
                    rho.setValue(ijk, float(1.0 - r * r));
                    vel.setValue(ijk, openvdb::Vec3s(speed));
                }
    }
};

/// A frame's surfaces, camera and light, rendered at the shutter's settings.
struct BlurScene {
    RenderSettings settings;
    SurfaceScene surfaces;
    FrameToRender frame;

    explicit BlurScene(IntegratorKind integrator, int samples)
    {
        surfaces.addStatic(0, makeBox({{-40, -2, -40}, {40, -1, 40}}), Transform{});
        settings.camera.position = Vec3d(0, 3, 16);
        settings.camera.lookAt = Vec3d(0, 2, 0);
        settings.image.width = 96;
        settings.image.height = 54;
        settings.image.samplesPerPixel = samples;
        settings.integrator.kind = integrator;
        settings.integrator.maxBounces = 2;
        settings.medium.extinction = 3.0;
        settings.sky.intensity = 0.02; // a night sky: what moves stands out against it
        frame.settings = &settings;
        frame.surfaces = &surfaces;
        frame.materials[0] = SurfaceMaterial::terrain();
        frame.secondsPerFrame = kSecondsPerFrame;
        frame.camera = Camera::fromSettings(settings.camera, settings.image.width, settings.image.height);
    }

    void setShutter(double open, double close)
    {
        settings.image.shutterOpen = open;
        settings.image.shutterClose = close;
    }
};

/// The mean of renders at kInstants instants spread evenly over the shutter,
/// each made by `atInstant(frames from the frame's instant)`.
template<typename RenderAt>
std::vector<double> meanOverInstants(const RenderAt& atInstant)
{
    std::vector<double> sum;
    for (int i = 0; i < kInstants; ++i) {
        const double t = kOpen + (i + 0.5) / kInstants * (kClose - kOpen);
        const RenderImage image = atInstant(t);
        sum.resize(image.rgba.size(), 0.0);
        for (std::size_t k = 0; k < sum.size(); ++k) sum[k] += image.rgba[k];
    }
    for (double& v : sum) v /= kInstants;
    return sum;
}

/// Two images of one size block by block: the sums of their pixels' mean
/// RGB, and how many of the 8x8-pixel blocks agree within 10%.
struct BlockAgreement {
    double sumA = 0.0, sumB = 0.0;
    int blocks = 0, agreeing = 0;
};
template<typename ImageA, typename ImageB>
BlockAgreement compareBlocks(int width, int height, const ImageA& a, const ImageB& b)
{
    const auto rgbMean = [width](const auto& rgba, int x, int y) {
        const std::size_t at = 4 * (std::size_t(y) * width + x);
        return (rgba[at] + rgba[at + 1] + rgba[at + 2]) / 3.0;
    };
    BlockAgreement agreement;
    for (int by = 0; by + 8 <= height; by += 8)
        for (int bx = 0; bx + 8 <= width; bx += 8) {
            double blockA = 0.0, blockB = 0.0;
            for (int y = by; y < by + 8; ++y)
                for (int x = bx; x < bx + 8; ++x) {
                    blockA += rgbMean(a, x, y);
                    blockB += rgbMean(b, x, y);
                }
            agreement.sumA += blockA;
            agreement.sumB += blockB;
            ++agreement.blocks;
            if (std::abs(blockA - blockB) <= 0.1 * std::max(blockB, 1e-3)) ++agreement.agreeing;
        }
    return agreement;
}

/// The relative RMS of the differences of two images' 8x8-pixel blocks (their mean RGB).
template<typename ImageA, typename ImageB>
double blockError(int width, int height, const ImageA& a, const ImageB& b)
{
    double squares = 0.0, reference = 0.0;
    for (int by = 0; by + 8 <= height; by += 8)
        for (int bx = 0; bx + 8 <= width; bx += 8) {
            double blockA = 0.0, blockB = 0.0;
            for (int y = by; y < by + 8; ++y)
                for (int x = bx; x < bx + 8; ++x)
                    for (int c = 0; c < 3; ++c) {
                        blockA += a[4 * (std::size_t(y) * width + x) + c];
                        blockB += b[4 * (std::size_t(y) * width + x) + c];
                    }
            squares += (blockA - blockB) * (blockA - blockB);
            reference += blockB * blockB;
        }
    return std::sqrt(squares / reference);
}

/// The blurred frame is the mean of its instants: their means within 2%,
/// and 90% of the 8x8-pixel blocks within 10%.
void checkBlurIsTheMeanOfInstants(const RenderImage& blurred, const std::vector<double>& instants)
{
    const BlockAgreement agreement = compareBlocks(blurred.width, blurred.height, blurred.rgba, instants);
    INFO("blurred " << agreement.sumA << ", the instants' mean " << agreement.sumB << "; " << agreement.agreeing << " of "
                    << agreement.blocks << " blocks within 10%");
    CHECK(agreement.sumA == Approx(agreement.sumB).epsilon(0.02));
    CHECK(agreement.agreeing >= 0.9 * agreement.blocks);
}

/// And it is blurred: the frame's instant alone, as the scene stands,
/// differs from the blurred frame in at least four blocks.
void checkTheInstantIsNotTheBlur(BlurScene& scene, const RenderImage& blurred)
{
    scene.setShutter(0.0, 0.0);
    scene.settings.image.samplesPerPixel *= 8;
    const RenderImage still = renderFrame(scene.frame);
    const BlockAgreement agreement = compareBlocks(still.width, still.height, still.rgba, blurred.rgba);
    INFO(agreement.agreeing << " of " << agreement.blocks << " blocks of the instant within 10% of the blurred frame");
    CHECK(agreement.blocks - agreement.agreeing >= 4);
}

} // namespace

TEST_CASE("motion blur: a cloud moving at constant velocity blurs into the mean of its instants", "[render][motion]")
{
    // 120 units a second: 2.5 units over the shutter, most of the ball's radius.
    const MovingBall ball(Vec3d(0, 3, 0), 3.5, 0.25, Vec3d(120, 0, 0));
    const CloudMotion motion(*ball.velocity, std::max(std::abs(kOpen), std::abs(kClose)) * kSecondsPerFrame);
    CHECK(motion.reach() == Approx(120 * 0.25 / 24).epsilon(1e-6));
    for (const IntegratorKind integrator : {IntegratorKind::Fast, IntegratorKind::Reference}) {
        INFO(enumName(integrator));
        BlurScene scene(integrator, integrator == IntegratorKind::Reference ? 256 : 32);
        const CloudLighting lighting(ball.density, scene.settings.medium, scene.settings.sun.direction, {});
        const CloudVolume volume(lighting, scene.settings.medium, scene.settings.integrator, motion.reach());
        scene.frame.volume = &volume;
        scene.frame.motion = &motion;
        scene.setShutter(kOpen, kClose);
        const RenderImage blurred = renderFrame(scene.frame);
        scene.settings.image.samplesPerPixel /= 8;
        const std::vector<double> instants = meanOverInstants([&](double t) {
            scene.setShutter(t, t);
            return renderFrame(scene.frame);
        });
        checkBlurIsTheMeanOfInstants(blurred, instants);
        checkTheInstantIsNotTheBlur(scene, blurred);
    }
}

TEST_CASE("motion blur: a moving object blurs into the mean of its instants, its poses slerped", "[render][motion]")
{
    // An aircraft-sized box crossing the view and turning a quarter turn over the shutter.
    Transform open, close;
    open.translation = Vec3d(-3, 3, 0);
    close.translation = Vec3d(3, 3, 0);
    close.rotation = Transform::rotationFromDegrees(Vec3d(0, 90, 0));
    for (const IntegratorKind integrator : {IntegratorKind::Fast, IntegratorKind::Reference}) {
        INFO(enumName(integrator));
        BlurScene scene(integrator, 64);
        scene.surfaces.addDynamic(1, makeBox({{-3, -0.5, -1}, {3, 0.5, 1}}));
        scene.surfaces.setMotion(1, open, close);
        scene.surfaces.commit();
        scene.setShutter(kOpen, kClose);
        const RenderImage blurred = renderFrame(scene.frame);
        scene.settings.image.samplesPerPixel /= 8;
        const std::vector<double> instants = meanOverInstants([&](double t) {
            scene.surfaces.setPose(1, interpolate(open, close, (t - kOpen) / (kClose - kOpen)));
            scene.surfaces.commit();
            scene.setShutter(t, t);
            return renderFrame(scene.frame);
        });
        checkBlurIsTheMeanOfInstants(blurred, instants);
        scene.surfaces.setPose(1, interpolate(open, close, 0.5));
        scene.surfaces.commit();
        checkTheInstantIsNotTheBlur(scene, blurred);
    }
}

TEST_CASE("motion blur: a following camera between its poses, a shutter that closes before it opens refused", "[render][motion]")
{
    const Camera a(Vec3d(0, 0, 10), Vec3d(0.0), Vec3d(0, 1, 0), 40, 64, 36);
    const Camera b(Vec3d(10, 0, 0), Vec3d(0.0), Vec3d(0, 1, 0), 60, 64, 36);
    const Camera half = Camera::between(a, b, 0.5);
    CHECK((half.position() - Vec3d(5, 0, 5)).length() < 1e-12);
    CHECK((half.forward() - Vec3d(-1, 0, -1).unitSafe()).length() < 1e-12);
    CHECK(half.tanHalfFov() == Approx(0.5 * (a.tanHalfFov() + b.tanHalfFov())));
    CHECK((Camera::between(a, b, 1.0).position() - b.position()).length() == 0.0);

    RenderSettings settings;
    settings.image.shutterOpen = 0.25;
    settings.image.shutterClose = -0.25;
    CHECK_THROWS_WITH(settings.validate(), Catch::Contains("shutter") && Catch::Contains("before it opens"));
}

TEST_CASE("tracks: a pose between two frames is theirs interpolated, and held beyond the track's ends", "[render][motion]")
{
    Tracks tracks;
    DynamicState state;
    state.pose.translation = Vec3d(0, 0, 0);
    tracks.add("plane", 1, state);
    state.pose.translation = Vec3d(4, 0, 0);
    state.pose.rotation = Transform::rotationFromDegrees(Vec3d(0, 90, 0));
    tracks.add("plane", 2, state);

    const Transform quarter = tracks.poseAt("plane", 1.25);
    CHECK((quarter.translation - Vec3d(1, 0, 0)).length() < 1e-12);
    const Vec3d nose = quarter.rotateToWorld(Vec3d(1, 0, 0)); // a quarter of the way through a quarter turn
    CHECK(std::atan2(-nose[2], nose[0]) * 180.0 / M_PI == Approx(22.5));
    CHECK((tracks.poseAt("plane", 0.75).translation - Vec3d(0.0)).length() == 0.0);
    CHECK((tracks.poseAt("plane", 2.25).translation - Vec3d(4, 0, 0)).length() == 0.0);
    CHECK(tracks.pathTo("plane", 1.5).size() == 2);
    CHECK(tracks.pathTo("plane", 1.5).back().translation[0] == Approx(2.0));
    CHECK_THROWS(tracks.poseAt("plane", 5.5));
}

TEST_CASE("paths over frames: a moving cloud's paths from the frames around, moved by its velocity, light it as its own do",
          "[render][motion]")
{
    // 48 units a second: two units a frame, more than half the ball's radius.
    const Vec3d speed(48, 0, 0);
    BlurScene scene(IntegratorKind::Fast, 8);
    MultipleScatteringSettings& paths = scene.settings.integrator.multipleScattering;
    paths.method = MultipleScatteringMethod::Paths;
    paths.pathFramesAround = 1;
    scene.settings.integrator.maxBounces = 64;
    // Frames 9, 10 and 11, each traced from its own ball.
    std::vector<ScatteredPaths> traced;
    const auto frameOf = [&](int frame, const CloudVolume& volume, const openvdb::Vec3SGrid& velocity) {
        FrameToRender f = scene.frame;
        f.frame = frame;
        f.volume = &volume;
        f.velocity = &velocity;
        return f;
    };
    for (int frame = 9; frame <= 11; ++frame) {
        const MovingBall ball(Vec3d(2.0 * (frame - 10), 3, 0), 3.5, 0.25, speed);
        const CloudLighting lighting(ball.density, scene.settings.medium, scene.settings.sun.direction, {});
        const CloudVolume volume(lighting, scene.settings.medium, scene.settings.integrator);
        traced.push_back(traceScatteredPaths(frameOf(frame, volume, *ball.velocity)));
    }
    const MovingBall ball(Vec3d(0, 3, 0), 3.5, 0.25, speed);
    const CloudLighting lighting(ball.density, scene.settings.medium, scene.settings.sun.direction, {});
    const CloudVolume volume(lighting, scene.settings.medium, scene.settings.integrator);
    scene.frame = frameOf(10, volume, *ball.velocity);
    const auto renderFrom = [&](const std::vector<ScatteredPaths>& frames) {
        scene.frame.scatteredPaths.clear();
        for (const ScatteredPaths& paths : frames) scene.frame.scatteredPaths.push_back(&paths);
        return renderFrame(scene.frame);
    };
    const RenderImage around = renderFrom(traced);
    // Frame 10's own light, from as many paths of its own.
    paths.pathFramesAround = 0;
    paths.pathsPerFrame *= 3;
    const RenderImage own = renderFrom({traceScatteredPaths(scene.frame)});
    const BlockAgreement moved = compareBlocks(own.width, own.height, around.rgba, own.rgba);
    INFO("over frames " << moved.sumA << ", its own " << moved.sumB << "; " << moved.agreeing << " of " << moved.blocks
                        << " blocks within 10%");
    CHECK(moved.sumA == Approx(moved.sumB).epsilon(0.02));
    CHECK(moved.agreeing >= 0.9 * moved.blocks);

    // Left where they scattered, the other frames' paths light the ball where it was.
    for (ScatteredPaths& frame : traced)
        for (ScatteredPaths::Path& path : frame.paths) path.velocity = Vec3d(0.0);
    paths.pathFramesAround = 1;
    const RenderImage unmoved = renderFrom(traced);
    const double movedError = blockError(own.width, own.height, around.rgba, own.rgba);
    const double unmovedError = blockError(own.width, own.height, unmoved.rgba, own.rgba);
    INFO("relative RMS of the 8x8 blocks against its own: moved " << movedError << ", unmoved " << unmovedError);
    CHECK(unmovedError > 2.0 * movedError);
}
