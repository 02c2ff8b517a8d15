#include <vfield/run/render_run.h>

#include <vfield/core/error.h>
#include <vfield/core/field_visitors.h>
#include <vfield/core/frame_file.h>
#include <vfield/folder/sim_folder.h>
#include <vfield/render/camera.h>
#include <vfield/run/render_backends.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/hash.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <utility>

namespace fs = std::filesystem;

namespace vfield {

namespace {

/// A frame made ready for a back-end: its view and what the view points to.
struct PreparedFrame {
    RenderSettings settings; ///< at the frame's instant
    DensityGrids grids;
    std::optional<CloudLighting> lighting;
    std::optional<CloudMotion> motion;
    std::optional<ScreenMotion> screenMotion;
    FrameView view;
};

/// What a frame's images depend on besides its simulation: every render
/// setting and the POV-Ray back-end's own, every surface's material, the
/// back-end and the formats. A frame
/// rendered with another stamp is stale (a killed 1280x720 run must not leave
/// its frames among a 960x540 rerun's).
uint64_t renderStamp(const RenderSettings& s, const PovraySettings& povray, const std::map<int, SurfaceMaterial>& materials,
                     const RenderRunOptions& options)
{
    ContentHash h;
    h.addValue(s.hash());
    hashFields(h, povray);
    for (const auto& [object, material] : materials) {
        h.addValue(int64_t(object));
        h.addValue(int64_t(material.kind));
        h.addValue(material.paint);
    }
    h.add(options.backend);
    for (const std::string& format : options.formats) h.add(format);
    return h.value();
}

} // namespace

RenderRunSummary renderScene(const Scene& scene, const std::string& simulationDir, const std::string& outputDir,
                             const RenderRunOptions& options)
{
    const SimulationSettings& setup = scene.simulation;
    const int first = options.firstFrame.value_or(setup.firstFrame), last = options.lastFrame.value_or(setup.lastFrame);
    if (first < setup.firstFrame || last > setup.lastFrame || last < first)
        throw ValueError("frames " + std::to_string(first) + "-" + std::to_string(last) + " are not within the scene's " +
                         std::to_string(setup.firstFrame) + "-" + std::to_string(setup.lastFrame));
    const RenderSettings& settings = scene.render;
    settings.validate();
    const FolderLock lock(outputDir, "vfield render", options.waitForFolder);
    const auto waitForFrame = [&](int frame) {
        if (options.waitForFrame) options.waitForFrame(frame);
    };
    waitForFrame(first);
    if (!fs::is_directory(simulationDir)) throw FileError(simulationDir, "no such simulation folder");
    const SimFolder simulation(simulationDir);
    // Every frame rendered must have been made by the folder's simulation.
    const StatsFile stats = simulation.readStats();
    const uint64_t inputsHash = stats.inputsHash;

    // Surfaces once: static meshes into one BVH, dynamic ones as instances.
    // Embree places a following camera and shadows the cloud for every back-end.
    SurfaceScene surfaces;
    std::map<int, SurfaceMaterial> materials;
    bool anyDynamic = false;
    std::vector<TriangleMesh> meshes;
    for (std::size_t i = 0; i < setup.objects.size(); ++i) meshes.push_back(makeMesh(setup.objects[i].mesh));
    for (std::size_t i = 0; i < setup.objects.size(); ++i) {
        const ObjectSettings& object = setup.objects[i];
        if (object.isDynamic) {
            surfaces.addDynamic(int(i), meshes[i]);
            anyDynamic = true;
        } else {
            surfaces.addStatic(int(i), meshes[i], object.transform);
        }
        materials[int(i)] = surfaceMaterialOf(object);
    }
    // Read again for each frame while the simulation is still writing them.
    Tracks tracks = anyDynamic ? simulation.readTracks() : Tracks();
    BBoxd terrainHeights(Vec3d(0.0), Vec3d(1.0));
    if (!surfaces.staticBounds().empty()) terrainHeights = surfaces.staticBounds();

    BackendInputs backendSetup;
    backendSetup.scene = &scene;
    backendSetup.meshes = &meshes;
    backendSetup.materials = &materials;
    backendSetup.surfaces = &surfaces;
    backendSetup.terrainLow = terrainHeights.min()[1];
    backendSetup.terrainHigh = terrainHeights.max()[1];
    backendSetup.outputDir = outputDir;
    backendSetup.formats = options.formats;
    const std::unique_ptr<RenderBackend> backend = makeRenderBackend(options.backend, backendSetup);
    if (options.warning)
        for (const std::string& line : backend->cannotDraw(settings)) options.warning(line);

    const int width = settings.image.width, height = settings.image.height;
    // Only EXR frames carry the passes, motion vectors among them.
    const bool screenMotionWanted =
        settings.image.passes && std::find(options.formats.begin(), options.formats.end(), "exr") != options.formats.end();
    // A shutter that closes after the frame's instant, and motion vectors,
    // see the next frame's poses: they wait for it too, so that a frame
    // rendered beside the simulation is the frame rendered after it.
    const bool seesNextFrame = settings.image.shutterClose > 0.0 || screenMotionWanted;
    const FirstSurfaceQuery firstSurface = [&surfaces](const Vec3d& origin, const Vec3d& dir, double tMin, double tMax) {
        SurfaceHit hit;
        return surfaces.intersect(origin, dir, tMin, tMax, hit) ? std::optional<double>(hit.distance) : std::nullopt;
    };
    // Surfaces shadow the cloud's light grid from the middle of the shutter
    // (the frame's instant for a shutter centred on it).
    const CloudLighting::Occlusion sunBlocked = [&surfaces](const Vec3d& origin, const Vec3d& dir) {
        return surfaces.occluded(origin, dir, 1e-3, std::numeric_limits<double>::max(), 0.5f);
    };

    // Each finished frame's stamp, beside the frames; unreadable: none finished.
    const fs::path out(outputDir);
    const std::string stampsPath = (out / "render-stamps.json").string();
    const std::string stamp = std::to_string(renderStamp(settings, scene.povray, materials, options));
    nlohmann::json stamps = nlohmann::json::object();
    if (fs::exists(stampsPath)) {
        std::ifstream in(stampsPath);
        stamps = nlohmann::json::parse(in, nullptr, false);
        if (!stamps.is_object()) stamps = nlohmann::json::object();
    }

    // Makes frame f, its grids read, ready for the back-end: places the
    // dynamic objects (and a following camera) at its instant and over the
    // shutter, and lights its cloud.
    const auto place = [&](int f, PreparedFrame& out) {
        // What moves, at the frame's instant and over the shutter.
        FrameView& view = out.view;
        view.frame = f;
        view.secondsPerFrame = 1.0 / setup.fps;
        out.settings = settings.at(f);
        view.settings = &out.settings;
        const ImageSettings& shutter = settings.image;
        const double open = f + shutter.shutterOpen, close = f + shutter.shutterClose;
        // The camera at an instant (its keys and path there), or following the path flown to it.
        const auto cameraAt = [&](double instant, const std::vector<Transform>& followedPath) {
            const CameraSettings camera = settings.camera.at(instant);
            return !followedPath.empty() ? followCamera(camera, followedPath, firstSurface, width, height)
                                         : Camera::fromSettings(camera, width, height);
        };
        // Where the camera and the dynamic objects stand at frame f + step,
        // or at f where the tracks do not reach that frame.
        const auto instantAt = [&](int step) {
            ScreenMotion::Instant instant{cameraAt(f + step, {}), {}};
            for (std::size_t i = 0; i < setup.objects.size(); ++i) {
                const ObjectSettings& object = setup.objects[i];
                if (!object.isDynamic) continue;
                const int at = tracks.holds(object.name, f + step) ? f + step : f;
                instant.poses[int(i)] = tracks.pose(object.name, at);
                if (settings.camera.follow && settings.camera.follow->object == object.name)
                    instant.camera = cameraAt(at, tracks.path(object.name, at));
            }
            return instant;
        };
        std::vector<Transform> framePath, openPath, closePath;
        for (std::size_t i = 0; i < setup.objects.size(); ++i) {
            const ObjectSettings& object = setup.objects[i];
            if (!object.isDynamic) continue;
            view.poses[int(i)] = tracks.pose(object.name, f);
            const Transform opening = tracks.poseAt(object.name, open);
            if (shutter.motionBlur()) surfaces.setMotion(int(i), opening, tracks.poseAt(object.name, close));
            else surfaces.setPose(int(i), opening);
            if (settings.camera.follow && settings.camera.follow->object == object.name) {
                framePath = tracks.path(object.name, f);
                openPath = tracks.pathTo(object.name, open);
                if (shutter.motionBlur()) closePath = tracks.pathTo(object.name, close);
            }
        }
        surfaces.commit();
        view.camera = cameraAt(f, framePath);
        if (shutter.seesMotion()) view.openingCamera = cameraAt(open, openPath);
        if (!closePath.empty() || (shutter.motionBlur() && settings.camera.moves()))
            view.closingCamera = cameraAt(close, closePath);
        // A frame looked at before keeps the cloud lit then, its surfaces as now.
        if (!out.lighting) out.lighting.emplace(out.grids.density, settings.medium, out.settings.sun.direction, sunBlocked);
        view.cloud = &*out.lighting;
        view.velocity = out.grids.velocity.get();
        if (shutter.seesMotion() && out.grids.velocity)
            view.motion =
                &out.motion.emplace(*out.grids.velocity, std::max(std::abs(shutter.shutterOpen), std::abs(shutter.shutterClose)) *
                                                             view.secondsPerFrame);
        if (screenMotionWanted)
            view.screenMotion =
                &out.screenMotion.emplace(instantAt(-1), ScreenMotion::Instant{view.camera, view.poses}, instantAt(1));
    };
    // The frames whose light frame f's render gathers: framesAround() either
    // side, shifted to stay within the scene's frames, or within those of a
    // simulation that stopped short of them (a look at a few frames).
    const int around = backend->framesAround();
    int lightFirst = setup.firstFrame, lightLast = setup.lastFrame;
    if (!options.waitForFrame && !stats.frames.empty()) {
        const auto [low, high] =
            std::minmax_element(stats.frames.begin(), stats.frames.end(),
                                [](const FrameRecord& a, const FrameRecord& b) { return a.frame < b.frame; });
        lightFirst = std::max(lightFirst, low->frame);
        lightLast = std::min(lightLast, high->frame);
    }
    const auto lightFrames = [&](int f) {
        const int span = std::min(2 * around, lightLast - lightFirst);
        const int from = std::clamp(f - around, lightFirst, lightLast - span);
        return std::pair(from, from + span);
    };
    std::set<int> seen; // frames the back-end has rendered or looked at
    // Frames looked at, kept for their own renders and for as long as the
    // back-end may hold on to them (RenderBackend::look).
    std::map<int, std::unique_ptr<PreparedFrame>> looked;

    RenderRunSummary summary;
    double seconds = 0.0;
    bool prepared = false;
    const int total = last - first + 1;
    for (int f = first; f <= last; ++f) {
        waitForFrame(seesNextFrame && f < setup.lastFrame ? f + 1 : f);
        if (anyDynamic && options.waitForFrame) tracks = simulation.readTracks();
        // Finished: rendered with these settings, and every output exists and
        // is newer than the frame's simulation (a frame simulated again since,
        // after an edit of the scene, is stale).
        const auto writeTime = [](const std::string& path) {
            std::error_code ec;
            const fs::file_time_type time = fs::last_write_time(path, ec);
            return ec ? fs::file_time_type::min() : time;
        };
        const fs::file_time_type simulated = writeTime(simulation.densityFile(f));
        const std::vector<std::string> outputs = backend->frameFiles(outputDir, f);
        // A frame whose light is gathered over frames records which.
        const auto [lightFrom, lightTo] = lightFrames(f);
        const std::string frameStamp =
            around > 0 ? stamp + " " + std::to_string(lightFrom) + "-" + std::to_string(lightTo) : stamp;
        const bool done = stamps.value(std::to_string(f), std::string()) == frameStamp &&
                          std::all_of(outputs.begin(), outputs.end(),
                                      [&](const std::string& p) { return fs::exists(p) && writeTime(p) >= simulated; });
        if (done && !options.force) {
            ++summary.skipped;
            continue;
        }
        const auto start = std::chrono::steady_clock::now();
        const auto frameProgress = [&](double fraction) {
            if (options.frameProgress) options.frameProgress(f, summary.rendered + summary.skipped, total, fraction);
        };
        // A frame the simulation did not make is refused before anything is said or prepared.
        std::unique_ptr<PreparedFrame> frame;
        if (const auto ahead = looked.find(f); ahead != looked.end()) {
            frame = std::move(ahead->second);
            looked.erase(ahead);
        } else {
            frame = std::make_unique<PreparedFrame>();
            frame->grids = simulation.readDensityGrids(f, inputsHash);
        }
        frameProgress(0.0);
        if (!prepared) backend->prepare();
        prepared = true;
        // The frames whose light the render gathers: those the back-end has
        // not seen are looked at first, each with its own surfaces placed.
        for (int g = lightFrom; g <= lightTo; ++g) {
            if (g == f || seen.count(g)) continue;
            waitForFrame(g);
            if (anyDynamic && options.waitForFrame) tracks = simulation.readTracks();
            auto neighbour = std::make_unique<PreparedFrame>();
            neighbour->grids = simulation.readDensityGrids(g, inputsHash);
            place(g, *neighbour);
            backend->look(neighbour->view);
            seen.insert(g);
            looked[g] = std::move(neighbour);
        }
        place(f, *frame);
        FrameView& view = frame->view;
        view.lightFrom = lightFrom;
        view.lightTo = lightTo;
        view.progress = frameProgress;
        backend->render(view, outputDir);
        seen.insert(f);
        // Behind us (rendered, finished or only looked at): released after
        // the render, where the back-end lets go of what it kept of them.
        looked.erase(looked.begin(), looked.lower_bound(f));
        stamps[std::to_string(f)] = frameStamp;
        writeTextAtomically(stampsPath, stamps.dump(1) + "\n");

        seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        ++summary.rendered;
        if (options.progress) options.progress(f, summary.rendered + summary.skipped, total, seconds);
    }
    if (summary.rendered > 0) {
        summary.secondsPerFrame = seconds / summary.rendered;
        for (const auto& [name, s] : backend->secondsByBackend()) summary.backendSecondsPerFrame[name] = s / summary.rendered;
    }
    return summary;
}

} // namespace vfield
