#include <vfield/scene/render_run.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>
#include <vfield/core/vdb_file.h>
#include <vfield/render/frame_image.h>
#include <vfield/render/povray_runner.h>
#include <vfield/render/povray_scene.h>
#include <vfield/scene/simulation_run.h>

#include <nlohmann/json.hpp>
#include <tbb/task_arena.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>

namespace fs = std::filesystem;

namespace vfield {

namespace {

/// Dynamic objects' poses per frame, from the simulation's tracks.json.
class Tracks {
public:
    Tracks(const std::string& path, bool required)
    {
        std::ifstream in(path);
        if (!in) {
            if (required) throw FileError(path, "no tracks of the dynamic objects (simulate the scene first)");
            return;
        }
        try {
            const nlohmann::json json = nlohmann::json::parse(in);
            for (const auto& [name, entries] : json.at("objects").items())
                for (const nlohmann::json& e : entries) {
                    Transform pose;
                    const auto p = e.at("position").get<std::vector<double>>();
                    const auto q = e.at("orientation").get<std::vector<double>>();
                    pose.translation = Vec3d(p.at(0), p.at(1), p.at(2));
                    pose.rotation = Quatd(q.at(0), q.at(1), q.at(2), q.at(3));
                    mPoses[name][e.at("frame").get<int>()] = pose;
                }
        } catch (const nlohmann::json::exception& e) {
            throw FileError(path, std::string("unreadable tracks: ") + e.what());
        }
        mPath = path;
    }

    Transform pose(const std::string& object, int frame) const
    {
        const auto o = mPoses.find(object);
        if (o != mPoses.end()) {
            const auto f = o->second.find(frame);
            if (f != o->second.end()) return f->second;
        }
        throw FileError(mPath, "no pose of \"" + object + "\" at frame " + std::to_string(frame));
    }

private:
    std::string mPath;
    std::map<std::string, std::map<int, Transform>> mPoses;
};

/// The frame's density grid, checked: present, a float grid named density, finite.
openvdb::FloatGrid::Ptr readDensity(const std::string& path)
{
    if (!fs::exists(path)) throw FileError(path, "missing (simulate these frames first)");
    for (const openvdb::GridBase::Ptr& grid : readVdb(path)) {
        if (grid->getName() != "density") continue;
        openvdb::FloatGrid::Ptr density = openvdb::gridPtrCast<openvdb::FloatGrid>(grid);
        if (!density) throw FileError(path, "grid 'density' is a " + grid->valueType() + " grid, not float");
        for (auto it = density->cbeginValueOn(); it; ++it)
            if (!std::isfinite(*it)) {
                const openvdb::Coord c = it.getCoord();
                throw FileError(path, "grid 'density' holds a non-finite value at voxel (" + std::to_string(c.x()) + ", " +
                                          std::to_string(c.y()) + ", " + std::to_string(c.z()) + ")");
            }
        return density;
    }
    throw FileError(path, "no grid named 'density'");
}

/// Behind and above the followed object in its heading frame, pulled in front
/// of any surface between the two so that the object stays in view.
Camera followCamera(const CameraSettings& settings, const Transform& object, const SurfaceScene& surfaces, int width, int height)
{
    Vec3d forward = object.rotateToWorld(Vec3d(1, 0, 0));
    forward[1] = 0.0;
    forward = forward.length() > 1e-9 ? forward.unitSafe() : Vec3d(1, 0, 0);
    const Vec3d up(0, 1, 0), right = forward.cross(up);
    const Vec3d& o = settings.followOffset;
    const Vec3d target = object.translation;
    Vec3d position = target + forward * o[0] + up * o[1] + right * o[2];
    const Vec3d toCamera = position - target;
    const double distance = toCamera.length();
    SurfaceHit hit;
    // Start past the object's own surfaces; stop short of where terrain begins.
    const double start = 0.25 * distance;
    if (distance > 0 && surfaces.intersect(target, toCamera / distance, start, distance, hit))
        position = target + toCamera / distance * std::max(start, 0.85 * hit.distance);
    return Camera::looking(settings, position, target, width, height);
}

SurfaceMaterial materialOf(const ObjectSpec& object)
{
    return object.mesh.kind == MeshSource::Kind::Terrain ? SurfaceMaterial::Terrain : SurfaceMaterial::Painted;
}

/// Writes a frame through POV-Ray: its scene files in the work folder, its
/// image renamed to `image`. The work folder holds meshes.inc already.
class PovrayBackend {
public:
    PovrayBackend(const Scene& scene, const std::vector<TriangleMesh>& meshes, const BBoxd& terrainHeights,
                  const std::string& workFolder, const RenderRunOptions& options)
        : mScene(scene), mFolder(workFolder), mKeep(options.keepScene)
    {
        std::vector<PovrayMesh> povrayMeshes;
        for (std::size_t i = 0; i < meshes.size(); ++i) {
            const ObjectSpec& object = scene.simulation.objects[i];
            PovrayMesh mesh;
            mesh.object = int(i);
            mesh.mesh = &meshes[i];
            mesh.material = materialOf(object);
            if (!object.isDynamic) {
                mesh.placement = object.transform;
                mStaticObjects.push_back(int(i));
            }
            povrayMeshes.push_back(mesh);
        }
        writeTextAtomically((fs::path(mFolder) / kMeshInclude).string(),
                            povrayMeshesText(povrayMeshes, terrainHeights.min()[1], terrainHeights.max()[1]));
        mOptions.threads = options.povrayThreads.value_or(tbb::this_task_arena::max_concurrency());
    }

    ~PovrayBackend()
    {
        if (mKeep) return;
        std::error_code ignored; // a folder still holding files (a failed frame's) stays
        fs::remove(fs::path(mFolder) / kMeshInclude, ignored);
        fs::remove(mFolder, ignored);
    }

    void render(int frame, const Camera& camera, const std::map<int, Transform>& poses, const openvdb::FloatGrid& density,
                const CloudVolume& volume, int width, int height, int samplesPerPixel, const std::string& image)
    {
        PovrayFrame pov;
        pov.settings = &mScene.render;
        pov.camera = camera;
        pov.frame = frame;
        pov.meshInclude = kMeshInclude;
        pov.staticObjects = mStaticObjects;
        pov.dynamicPoses = poses;
        const std::string df3 = frameFileName("density", frame, "df3"), skyLitDf3 = frameFileName("sky_lit", frame, "df3"),
                          scene = frameFileName("frame", frame, "pov"), rendered = frameFileName("render", frame, "png");
        const fs::path folder(mFolder);
        if (!density.empty()) {
            PovrayCloud cloud;
            cloud.df3File = df3;
            cloud.placement = writeDf3(density, (folder / df3).string());
            cloud.volumeStep = mScene.render.image.volumeStep;
            cloud.skyLitDf3File = skyLitDf3;
            cloud.skyLitPlacement = writeDf3(*volume.skyLitDensity(), (folder / cloud.skyLitDf3File).string());
            pov.cloud = cloud;
        }
        writeTextAtomically((folder / scene).string(), povrayFrameText(pov));
        PovrayOptions options = mOptions;
        options.width = width;
        options.height = height;
        options.samplesPerPixel = samplesPerPixel;
        try {
            runPovray(mFolder, scene, rendered, options);
        } catch (...) {
            mKeep = true; // a failed frame's scene files and log stay for inspection
            throw;
        }
        fs::create_directories(fs::path(image).parent_path());
        fs::rename(folder / rendered, image);
        if (!mKeep)
            for (const std::string& file : {df3, skyLitDf3, scene, rendered + ".log"}) fs::remove(folder / file);
    }

private:
    static constexpr const char* kMeshInclude = "meshes.inc";
    const Scene& mScene;
    std::string mFolder;
    bool mKeep;
    PovrayOptions mOptions;
    std::vector<int> mStaticObjects;
};

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
    for (const std::string& format : options.formats)
        if (format != "png" && format != "exr") throw ValueError("unknown image format '" + format + "' (png or exr)");
    const bool useEmbree = options.backend != RenderBackend::Povray, usePovray = options.backend != RenderBackend::Embree;
    if (options.backend == RenderBackend::Povray && options.formats != std::vector<std::string>{"png"})
        throw ValueError("the POV-Ray back-end writes png images only");
    const bool both = options.backend == RenderBackend::Both;
    if (both && std::find(options.formats.begin(), options.formats.end(), "png") == options.formats.end())
        throw ValueError("the side-by-side images of both back-ends are png: include png in the formats");
    if (usePovray) requirePovray();

    // Surfaces once: static meshes into one BVH, dynamic ones as instances.
    // Embree places a following camera for either back-end.
    SurfaceScene surfaces;
    FrameToRender frame;
    frame.settings = &scene.render;
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
        frame.materials[int(i)] = materialOf(object);
    }
    const Tracks tracks((fs::path(simulationDir) / "tracks.json").string(), anyDynamic);
    BBoxd terrainHeights(Vec3d(0.0), Vec3d(1.0));
    if (!surfaces.staticBounds().empty()) terrainHeights = surfaces.staticBounds();
    frame.terrainLow = terrainHeights.min()[1];
    frame.terrainHigh = terrainHeights.max()[1];
    frame.width = options.width.value_or(scene.render.image.width);
    frame.height = options.height.value_or(scene.render.image.height);
    frame.samplesPerPixel = options.samplesPerPixel.value_or(scene.render.image.samplesPerPixel);

    const fs::path out(outputDir);
    std::unique_ptr<PovrayBackend> povray;

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
        const bool done = std::all_of(outputs.begin(), outputs.end(), [](const std::string& p) { return fs::exists(p); });
        if (done && !options.force) {
            ++summary.skipped;
            continue;
        }
        const auto start = std::chrono::steady_clock::now();
        const std::string densityPath = (fs::path(simulationDir) / frameFileName("density", f, "vdb")).string();
        const openvdb::FloatGrid::Ptr density = readDensity(densityPath);

        std::optional<Transform> followed;
        std::map<int, Transform> poses;
        for (std::size_t i = 0; i < setup.objects.size(); ++i) {
            const ObjectSpec& object = setup.objects[i];
            if (!object.isDynamic) continue;
            Transform pose = tracks.pose(object.name, f);
            pose.scale = object.transform.scale;
            surfaces.setPose(int(i), pose);
            poses[int(i)] = pose;
            if (scene.render.camera.followObject && *scene.render.camera.followObject == object.name) followed = pose;
        }
        surfaces.commit();
        frame.camera = followed ? followCamera(scene.render.camera, *followed, surfaces, frame.width, frame.height)
                                : Camera::fromSettings(scene.render.camera, frame.width, frame.height);
        frame.frame = f;

        const CloudVolume volume(density, scene.render.image, scene.render.sun.direction, &surfaces);
        if (useEmbree) {
            const auto embreeStart = std::chrono::steady_clock::now();
            frame.volume = volume.empty() ? nullptr : &volume;
            const RenderImage image = renderFrame(frame);
            for (const std::string& path : embreeImages) writeFrameImage(image, path);
            embreeSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - embreeStart).count();
        }
        if (usePovray) {
            const auto povrayStart = std::chrono::steady_clock::now();
            if (!povray)
                povray = std::make_unique<PovrayBackend>(scene, meshes, terrainHeights, (out / "povray-scene").string(), options);
            povray->render(f, frame.camera, poses, *density, volume, frame.width, frame.height, frame.samplesPerPixel,
                           povrayImage);
            povraySeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - povrayStart).count();
        }
        if (both) writeSideBySide(((out / "embree") / frameFileName("frame", f, "png")).string(), povrayImage, sideBySide);

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
