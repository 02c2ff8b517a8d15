// What the raw libraries do on the same data, so that every stage is reported
// as a ratio measured in one run:
//  - raw Embree: a primary ray per sample (one through a pixel's centre, or
//    the showcase's own count jittered over it) and a shadow ray per hit
//    over TBB tiles on the showcase terrain, one at a time (rtcIntersect1 /
//    rtcOccluded1) and in 8-wide packets (rtcIntersect8 / rtcOccluded8, as
//    vfield traces them), against vfield's surface-only frame;
//  - a raw OpenVDB trilinear sampler loop over the showcase's force grid and
//    particles in spawn order, against vfield's advection;
//  - POV-Ray on the same frame and settings as vfield's cloud frame.

#include "bench_showcase.h"

#include <vfield/core/atomic_file.h>
#include <vfield/render/embree/sample_random.h>
#include <vfield/render/povray/df3.h>
#include <vfield/render/povray/povray_runner.h>
#include <vfield/render/povray/povray_scene.h>

#include <benchmark/benchmark.h>

#include <embree3/rtcore.h>
#include <openvdb/tools/Interpolation.h>
#include <tbb/blocked_range.h>
#include <tbb/blocked_range2d.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <filesystem>
#include <limits>

using namespace vfield;
using namespace vfield::bench;

namespace {

/// The showcase terrain in one Embree scene, nothing else.
struct RawEmbree {
    RTCDevice device = rtcNewDevice(nullptr);
    RTCScene scene = rtcNewScene(device);

    explicit RawEmbree(const TriangleMesh& mesh)
    {
        RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, mesh.points.data(), 0, sizeof(Vec3f),
                                   mesh.points.size());
        rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh.triangles.data(), 0, sizeof(Vec3ui),
                                   mesh.triangles.size());
        rtcCommitGeometry(geometry);
        rtcAttachGeometry(scene, geometry);
        rtcReleaseGeometry(geometry);
        rtcCommitScene(scene);
    }
    ~RawEmbree()
    {
        rtcReleaseScene(scene);
        rtcReleaseDevice(device);
    }
};

/// One ray at a time: a primary ray per sample and a shadow ray per hit.
void rawEmbreeOneAtATime(benchmark::State& state, const RawEmbree& raw, ShowcaseFrame& s, int width, int height,
                         int samplesPerPixel)
{
    const Camera camera = Camera::fromSettings(s.scene.render.camera, width, height);
    const Vec3f toSun(s.scene.render.sun.direction.unitSafe());
    std::vector<float> shade(std::size_t(width) * height);
    for (auto _ : state) {
        tbb::parallel_for(tbb::blocked_range2d<int>(0, height, 16, 0, width, 16), [&](const tbb::blocked_range2d<int>& r) {
            RTCIntersectContext context;
            rtcInitIntersectContext(&context);
            for (int y = r.rows().begin(); y != r.rows().end(); ++y)
                for (int x = r.cols().begin(); x != r.cols().end(); ++x) {
                    const uint32_t pixel = uint32_t(y) * uint32_t(width) + uint32_t(x);
                    float value = 0.0f;
                    // One ray through the centre, or each jittered over the pixel, as vfield's.
                    for (int sample = 0; sample < samplesPerPixel; ++sample) {
                        SampleRandom random(0, pixel, uint32_t(sample));
                        const double jx = samplesPerPixel == 1 ? 0.5 : random.next();
                        const double jy = samplesPerPixel == 1 ? 0.5 : random.next();
                        const Vec3d dir = camera.direction(x + jx, y + jy);
                        RTCRayHit hit{};
                        hit.ray.org_x = float(camera.position()[0]);
                        hit.ray.org_y = float(camera.position()[1]);
                        hit.ray.org_z = float(camera.position()[2]);
                        hit.ray.dir_x = float(dir[0]);
                        hit.ray.dir_y = float(dir[1]);
                        hit.ray.dir_z = float(dir[2]);
                        hit.ray.tfar = std::numeric_limits<float>::infinity();
                        hit.ray.mask = ~0u;
                        hit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                        rtcIntersect1(raw.scene, &context, &hit);
                        if (hit.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
                        RTCRay shadow{};
                        shadow.org_x = hit.ray.org_x + hit.ray.dir_x * hit.ray.tfar * 0.999f;
                        shadow.org_y = hit.ray.org_y + hit.ray.dir_y * hit.ray.tfar * 0.999f;
                        shadow.org_z = hit.ray.org_z + hit.ray.dir_z * hit.ray.tfar * 0.999f;
                        shadow.dir_x = toSun[0];
                        shadow.dir_y = toSun[1];
                        shadow.dir_z = toSun[2];
                        shadow.tfar = std::numeric_limits<float>::infinity();
                        shadow.mask = ~0u;
                        rtcOccluded1(raw.scene, &context, &shadow);
                        value += shadow.tfar < 0.0f ? 0.5f : 1.0f;
                    }
                    shade[pixel] = value / float(samplesPerPixel);
                }
        });
        benchmark::DoNotOptimize(shade.data());
    }
}

/// A lane of a packet: a ray from origin along dir, to infinity.
void setLane(RTCRay8& ray, int lane, const Vec3f& origin, const Vec3d& dir)
{
    ray.org_x[lane] = origin[0];
    ray.org_y[lane] = origin[1];
    ray.org_z[lane] = origin[2];
    ray.dir_x[lane] = float(dir[0]);
    ray.dir_y[lane] = float(dir[1]);
    ray.dir_z[lane] = float(dir[2]);
    ray.tfar[lane] = std::numeric_limits<float>::infinity();
    ray.mask[lane] = ~0u;
}

/// The same rays eight neighbouring pixels of a row at a time, as vfield
/// traces them (Embree's 8-wide packets, coherent): a sample's primary rays,
/// then the shadow rays of those that hit.
void rawEmbreePackets(benchmark::State& state, const RawEmbree& raw, ShowcaseFrame& s, int width, int height, int samplesPerPixel)
{
    const Camera camera = Camera::fromSettings(s.scene.render.camera, width, height);
    const Vec3f eye(camera.position()), toSun(s.scene.render.sun.direction.unitSafe());
    std::vector<float> shade(std::size_t(width) * height);
    for (auto _ : state) {
        tbb::parallel_for(tbb::blocked_range2d<int>(0, height, 16, 0, width, 16), [&](const tbb::blocked_range2d<int>& r) {
            RTCIntersectContext context;
            rtcInitIntersectContext(&context);
            context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
            for (int y = r.rows().begin(); y != r.rows().end(); ++y)
                for (int x0 = r.cols().begin(); x0 < r.cols().end(); x0 += 8) {
                    const int count = std::min(8, r.cols().end() - x0);
                    float value[8] = {};
                    for (int sample = 0; sample < samplesPerPixel; ++sample) {
                        alignas(32) int valid[8] = {}, shadowValid[8] = {};
                        alignas(32) RTCRayHit8 hit{};
                        for (int lane = 0; lane < count; ++lane) {
                            // One ray through the centre, or each jittered over the pixel, as vfield's.
                            SampleRandom random(0, uint32_t(y) * uint32_t(width) + uint32_t(x0 + lane), uint32_t(sample));
                            const double jx = samplesPerPixel == 1 ? 0.5 : random.next();
                            const double jy = samplesPerPixel == 1 ? 0.5 : random.next();
                            valid[lane] = -1;
                            setLane(hit.ray, lane, eye, camera.direction(x0 + lane + jx, y + jy));
                            hit.hit.geomID[lane] = RTC_INVALID_GEOMETRY_ID;
                        }
                        rtcIntersect8(valid, raw.scene, &context, &hit);
                        alignas(32) RTCRay8 shadow{};
                        for (int lane = 0; lane < count; ++lane) {
                            if (hit.hit.geomID[lane] == RTC_INVALID_GEOMETRY_ID) continue;
                            shadowValid[lane] = -1;
                            const float t = hit.ray.tfar[lane] * 0.999f;
                            setLane(shadow, lane,
                                    Vec3f(hit.ray.org_x[lane] + hit.ray.dir_x[lane] * t,
                                          hit.ray.org_y[lane] + hit.ray.dir_y[lane] * t,
                                          hit.ray.org_z[lane] + hit.ray.dir_z[lane] * t),
                                    Vec3d(toSun));
                        }
                        rtcOccluded8(shadowValid, raw.scene, &context, &shadow);
                        for (int lane = 0; lane < count; ++lane)
                            if (shadowValid[lane]) value[lane] += shadow.tfar[lane] < 0.0f ? 0.5f : 1.0f;
                    }
                    for (int lane = 0; lane < count; ++lane)
                        shade[std::size_t(y) * width + x0 + lane] = value[lane] / float(samplesPerPixel);
                }
        });
        benchmark::DoNotOptimize(shade.data());
    }
}

void BM_RawEmbreeRays(benchmark::State& state)
{
    ShowcaseFrame& s = showcase();
    static RawEmbree raw(s.terrain);
    const int width = int(state.range(0)), height = int(state.range(1)), samplesPerPixel = int(state.range(2));
    if (state.range(3) != 0) rawEmbreePackets(state, raw, s, width, height, samplesPerPixel);
    else rawEmbreeOneAtATime(state, raw, s, width, height, samplesPerPixel);
    state.counters["primary_rays_per_s"] =
        benchmark::Counter(double(width) * height * samplesPerPixel, benchmark::Counter::kIsIterationInvariantRate);
}
// At one sample a pixel and at the showcase's own (kShowcaseSamplesPerPixel),
// one ray at a time and in packets.
BENCHMARK(BM_RawEmbreeRays)
    ->ArgNames({"w", "h", "spp", "packets"})
    ->ArgsProduct({{640}, {360}, {1, kShowcaseSamplesPerPixel}, {0, 1}})
    ->ArgsProduct({{1280}, {720}, {1, kShowcaseSamplesPerPixel}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// One explicit Euler step of every particle of the main job at frame 120
/// through the trilinearly sampled static force grid, gravity, wind and
/// drag: the least an advection step can do.
void BM_RawSamplerAdvection(benchmark::State& state)
{
    const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(1)));
    MainJobFrame& job = mainJobAtFrame120(state.range(0));
    job.simulator->restoreState(job.state);
    const openvdb::Vec3SGrid::Ptr forces = job.simulator->staticForceGrid();
    const openvdb::Vec3SGrid& force = *forces;
    std::vector<Vec3f> position = job.simulator->particles().position, velocity = job.simulator->particles().velocity;
    const Vec3f uniform(15.0f, -9.81f, 0.0f);
    const float drag = 0.4f, dt = 1.0f / 240.0f;
    for (auto _ : state) {
        tbb::parallel_for(
            tbb::blocked_range<std::size_t>(0, position.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
                // A sampler keeps a pointer to its accessor: the accessor must outlive it.
                const openvdb::Vec3SGrid::ConstAccessor accessor = force.getConstAccessor();
                const openvdb::tools::GridSampler<openvdb::Vec3SGrid::ConstAccessor, openvdb::tools::BoxSampler> sampler(
                    accessor, force.transform());
                for (std::size_t p = r.begin(); p != r.end(); ++p) {
                    const Vec3f a = sampler.wsSample(Vec3d(position[p])) + uniform - velocity[p] * drag;
                    velocity[p] += a * dt;
                    position[p] += velocity[p] * dt;
                }
            });
    }
    state.counters["particle_steps_per_s"] =
        benchmark::Counter(double(position.size()), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_RawSamplerAdvection)
    ->ArgNames({"particles", "threads"})
    ->Args({1'000'000, 1})
    ->Args({1'000'000, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// vfield's POV-Ray back-end on the showcase's frame 100: df3 export, scene
/// text and a povray run, at the settings of BM_RenderCloud's first case.
void BM_PovrayFrame(benchmark::State& state)
{
    if (!povrayAvailable()) {
        state.SkipWithError("povray is not installed");
        return;
    }
    ShowcaseFrame& s = showcase();
    const int width = int(state.range(0)), height = int(state.range(1));
    const std::string dir = (std::filesystem::temp_directory_path() / "vfield-bench-povray").string();
    std::filesystem::create_directories(dir);
    writeTextAtomically(dir + "/meshes.inc",
                        povrayMeshesText({{0, &s.terrain, SurfaceMaterial::terrain(), Transform{}}},
                                         s.surfaces.staticBounds().min()[1], s.surfaces.staticBounds().max()[1]));
    const RenderSettings settings = s.settings(width, height, int(state.range(2)));
    for (auto _ : state) {
        const CloudLighting lighting(s.density, settings.medium, settings.sun.direction, s.sunBlocked());
        PovrayFrame frame;
        frame.settings = &settings;
        frame.camera = Camera::fromSettings(s.scene.render.camera, width, height);
        frame.frame = 100;
        frame.meshInclude = "meshes.inc";
        frame.staticObjects = {0};
        PovrayCloud cloud;
        cloud.df3File = "density.df3";
        cloud.placement = writeDf3(*s.density, dir + "/density.df3");
        cloud.skyLitDf3File = "sky_lit.df3";
        cloud.skyLitPlacement = writeDf3(*lighting.skyLitDensity(), dir + "/sky_lit.df3");
        frame.cloud = cloud;
        writeTextAtomically(dir + "/frame.pov", povrayFrameText(frame));
        runPovray(dir, "frame.pov", "frame.exr", settings.image, PovrayQuality::Final, 2);
    }
}
BENCHMARK(BM_PovrayFrame)
    ->ArgNames({"w", "h", "spp"})
    ->Args({320, 180, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

} // namespace
