#include <vfield/scene/render_run.h>

#include <vfield/core/error.h>
#include <vfield/core/frame_file.h>
#include <vfield/render/embree/renderer.h>
#include <vfield/render/frame_image.h>
#include <vfield/render/povray/povray_backend.h>
#include <vfield/render/povray/povray_runner.h>
#include <vfield/scene/sim_folder.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/hash.h>

#include <nlohmann/json.hpp>
#include <tbb/task_arena.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>

namespace fs = std::filesystem;

namespace vfield {

SurfaceMaterial surfaceMaterialOf(const ObjectSpec& object)
{
    const bool isGround = object.mesh.kind == MeshSource::Kind::Terrain || object.mesh.kind == MeshSource::Kind::Heightmap;
    return isGround ? SurfaceMaterial::terrain() : SurfaceMaterial::painted(object.color);
}

namespace {

/// What a frame's images depend on besides its simulation: every render
/// setting, every surface's material, the back-end and the formats. A frame
/// rendered with another stamp is stale (a killed 1280x720 run must not leave
/// its frames among a 960x540 rerun's).
uint64_t renderStamp(const RenderSettings& s, const std::map<int, SurfaceMaterial>& materials, const RenderRunOptions& options)
{
    ContentHash h;
    h.addValue(s.hash());
    for (const auto& [object, material] : materials) {
        h.addValue(int64_t(object));
        h.addValue(int64_t(material.kind));
        h.addValue(material.paint);
    }
    h.addValue(int64_t(options.backend));
    for (const std::string& format : options.formats) h.add(format);
    return h.value();
}

} // namespace

RenderRunSummary renderScene(const Scene& scene, const std::string& simulationDir, const std::string& outputDir,
                             const RenderRunOptions& options)
{
    const SimulationSetup& setup = scene.simulation;
    const int first = options.firstFrame.value_or(setup.firstFrame), last = options.lastFrame.value_or(setup.lastFrame);
    if (first < setup.firstFrame || last > setup.lastFrame || last < first)
        throw ValueError("frames " + std::to_string(first) + "-" + std::to_string(last) + " are not within the scene's " +
                         std::to_string(setup.firstFrame) + "-" + std::to_string(setup.lastFrame));
    if (!fs::is_directory(simulationDir)) throw FileError(simulationDir, "no such simulation folder");
    const SimFolder simulation(simulationDir);
    const RenderSettings& settings = scene.render;
    settings.validate();
    for (const std::string& format : options.formats)
        if (format != "png" && format != "exr") throw ValueError("unknown image format '" + format + "' (png or exr)");
    const bool useEmbree = options.backend != RenderBackend::Povray, usePovray = options.backend != RenderBackend::Embree;
    if (options.backend == RenderBackend::Povray && options.formats != std::vector<std::string>{"png"})
        throw ValueError("the POV-Ray back-end writes png images only");
    if (usePovray && settings.image.transparentSky)
        throw ValueError("a transparent sky is for EXR frames of the Embree back-end; the POV-Ray back-end draws the sky");
    const bool both = options.backend == RenderBackend::Both;
    if (both && std::find(options.formats.begin(), options.formats.end(), "png") == options.formats.end())
        throw ValueError("the side-by-side images of both back-ends are png: include png in the formats");
    if (usePovray) requirePovray();

    // Surfaces once: static meshes into one BVH, dynamic ones as instances.
    // Embree places a following camera for either back-end.
    SurfaceScene surfaces;
    FrameToRender frame;
    frame.settings = &settings;
    frame.surfaces = &surfaces;
    bool anyDynamic = false;
    std::vector<TriangleMesh> meshes;
    for (std::size_t i = 0; i < setup.objects.size(); ++i) {
        const ObjectSpec& object = setup.objects[i];
        meshes.push_back(makeMesh(object.mesh));
        if (object.isDynamic) {
            surfaces.addDynamic(int(i), meshes.back());
            anyDynamic = true;
        } else {
            surfaces.addStatic(int(i), meshes.back(), object.transform);
        }
        frame.materials[int(i)] = surfaceMaterialOf(object);
    }
    const Tracks tracks = anyDynamic ? simulation.readTracks() : Tracks();
    BBoxd terrainHeights(Vec3d(0.0), Vec3d(1.0));
    if (!surfaces.staticBounds().empty()) terrainHeights = surfaces.staticBounds();
    frame.terrainLow = terrainHeights.min()[1];
    frame.terrainHigh = terrainHeights.max()[1];
    const int width = settings.image.width, height = settings.image.height;
    const FirstSurfaceQuery firstSurface = [&surfaces](const Vec3d& origin, const Vec3d& dir, double tMin, double tMax) {
        SurfaceHit hit;
        return surfaces.intersect(origin, dir, tMin, tMax, hit) ? std::optional<double>(hit.distance) : std::nullopt;
    };
    const CloudLighting::Occlusion sunBlocked = [&surfaces](const Vec3d& origin, const Vec3d& dir) {
        return surfaces.occluded(origin, dir, 1e-3, std::numeric_limits<double>::max());
    };

    const fs::path out(outputDir);
    std::unique_ptr<PovrayBackend> povray;
    // Each finished frame's stamp, beside the frames; unreadable: none finished.
    const std::string stampsPath = (out / "render-stamps.json").string();
    const std::string stamp = std::to_string(renderStamp(settings, frame.materials, options));
    nlohmann::json stamps = nlohmann::json::object();
    if (fs::exists(stampsPath)) {
        std::ifstream in(stampsPath);
        stamps = nlohmann::json::parse(in, nullptr, false);
        if (!stamps.is_object()) stamps = nlohmann::json::object();
    }

    RenderRunSummary summary;
    double seconds = 0.0, embreeSeconds = 0.0, povraySeconds = 0.0;
    const int total = last - first + 1;
    for (int f = first; f <= last; ++f) {
        // What this frame writes, by back-end.
        std::vector<std::string> embreeImages, outputs;
        for (const std::string& format : options.formats)
            if (useEmbree) embreeImages.push_back(((both ? out / "embree" : out) / frameFileName("frame", f, format)).string());
        const std::string povrayImage = ((both ? out / "povray" : out) / frameFileName("frame", f, "png")).string();
        const std::string sideBySide = (out / frameFileName("frame", f, "png")).string();
        outputs = embreeImages;
        if (usePovray) outputs.push_back(povrayImage);
        if (both) outputs.push_back(sideBySide);
        // Finished: rendered with these settings, and every output exists and
        // is newer than the frame's simulation (a frame simulated again since,
        // after an edit of the scene, is stale).
        const auto writeTime = [](const std::string& path) {
            std::error_code ec;
            const fs::file_time_type time = fs::last_write_time(path, ec);
            return ec ? fs::file_time_type::min() : time;
        };
        const fs::file_time_type simulated = writeTime(simulation.densityFile(f));
        const bool done = stamps.value(std::to_string(f), std::string()) == stamp &&
                          std::all_of(outputs.begin(), outputs.end(),
                                      [&](const std::string& p) { return fs::exists(p) && writeTime(p) >= simulated; });
        if (done && !options.force) {
            ++summary.skipped;
            continue;
        }
        const auto start = std::chrono::steady_clock::now();
        const openvdb::FloatGrid::Ptr density = simulation.readDensity(f);

        std::vector<Transform> followedPath;
        std::map<int, Transform> poses;
        for (std::size_t i = 0; i < setup.objects.size(); ++i) {
            const ObjectSpec& object = setup.objects[i];
            if (!object.isDynamic) continue;
            const Transform pose = tracks.pose(object.name, f);
            surfaces.setPose(int(i), pose);
            poses[int(i)] = pose;
            if (settings.camera.follow && settings.camera.follow->object == object.name)
                followedPath = tracks.path(object.name, f);
        }
        surfaces.commit();
        frame.camera = !followedPath.empty() ? followCamera(settings.camera, followedPath, firstSurface, width, height)
                                             : Camera::fromSettings(settings.camera, width, height);
        frame.frame = f;

        const CloudLighting lighting(density, settings.medium, settings.sun.direction, sunBlocked);
        const CloudVolume volume(lighting, settings.medium, settings.integrator);
        if (useEmbree) {
            const auto embreeStart = std::chrono::steady_clock::now();
            frame.volume = volume.empty() ? nullptr : &volume;
            const RenderImage image = renderFrame(frame);
            for (const std::string& path : embreeImages) writeFrameImage(image, path);
            embreeSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - embreeStart).count();
        }
        if (usePovray) {
            const auto povrayStart = std::chrono::steady_clock::now();
            if (!povray) {
                std::vector<PovrayMesh> povrayMeshes;
                for (std::size_t i = 0; i < meshes.size(); ++i) {
                    const ObjectSpec& object = setup.objects[i];
                    povrayMeshes.push_back({int(i), &meshes[i], surfaceMaterialOf(object),
                                            object.isDynamic ? std::nullopt : std::optional<Transform>(object.transform)});
                }
                PovrayBackendOptions povrayOptions;
                povrayOptions.workFolder = (out / "povray-scene").string();
                povrayOptions.keepScene = options.keepScene;
                povrayOptions.threads = options.povrayThreads.value_or(tbb::this_task_arena::max_concurrency());
                povray = std::make_unique<PovrayBackend>(povrayMeshes, terrainHeights.min()[1], terrainHeights.max()[1], settings,
                                                         povrayOptions);
            }
            povray->render(f, frame.camera, poses, lighting, povrayImage);
            povraySeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - povrayStart).count();
        }
        if (both) writeSideBySide(((out / "embree") / frameFileName("frame", f, "png")).string(), povrayImage, sideBySide);
        stamps[std::to_string(f)] = stamp;
        writeTextAtomically(stampsPath, stamps.dump(1) + "\n");

        seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        ++summary.rendered;
        if (options.progress) options.progress(f, summary.rendered + summary.skipped, total, seconds);
    }
    if (summary.rendered > 0) {
        summary.secondsPerFrame = seconds / summary.rendered;
        summary.embreeSecondsPerFrame = embreeSeconds / summary.rendered;
        summary.povraySecondsPerFrame = povraySeconds / summary.rendered;
    }
    return summary;
}

} // namespace vfield
