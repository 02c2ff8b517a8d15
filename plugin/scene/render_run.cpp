#include <vfield/scene/render_run.h>

#include <vfield/core/error.h>
#include <vfield/core/vdb_file.h>
#include <vfield/render/frame_image.h>
#include <vfield/scene/simulation_run.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
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

    // Surfaces once: static meshes into one BVH, dynamic ones as instances.
    SurfaceScene surfaces;
    FrameToRender frame;
    frame.settings = &scene.render;
    frame.surfaces = &surfaces;
    bool anyDynamic = false;
    for (std::size_t i = 0; i < setup.objects.size(); ++i) {
        const ObjectSpec& object = setup.objects[i];
        const TriangleMesh mesh = makeMesh(object.mesh);
        if (object.isDynamic) {
            surfaces.addDynamic(int(i), mesh);
            anyDynamic = true;
        } else {
            surfaces.addStatic(int(i), mesh, object.transform);
        }
        frame.materials[int(i)] = object.mesh.kind == MeshSource::Kind::Terrain ? SurfaceMaterial::Terrain : SurfaceMaterial::Painted;
    }
    const Tracks tracks((fs::path(simulationDir) / "tracks.json").string(), anyDynamic);
    if (!surfaces.staticBounds().empty()) {
        frame.terrainLow = surfaces.staticBounds().min()[1];
        frame.terrainHigh = surfaces.staticBounds().max()[1];
    }
    frame.width = options.width.value_or(scene.render.image.width);
    frame.height = options.height.value_or(scene.render.image.height);
    frame.samplesPerPixel = options.samplesPerPixel.value_or(scene.render.image.samplesPerPixel);

    RenderRunSummary summary;
    double seconds = 0.0;
    const int total = last - first + 1;
    for (int f = first; f <= last; ++f) {
        std::vector<std::string> outputs;
        for (const std::string& format : options.formats)
            outputs.push_back((fs::path(outputDir) / frameFileName("frame", f, format)).string());
        const bool done = std::all_of(outputs.begin(), outputs.end(), [](const std::string& p) { return fs::exists(p); });
        if (done && !options.force) {
            ++summary.skipped;
            continue;
        }
        const auto start = std::chrono::steady_clock::now();
        const std::string densityPath = (fs::path(simulationDir) / frameFileName("density", f, "vdb")).string();
        const openvdb::FloatGrid::Ptr density = readDensity(densityPath);

        std::optional<Transform> followed;
        for (std::size_t i = 0; i < setup.objects.size(); ++i) {
            const ObjectSpec& object = setup.objects[i];
            if (!object.isDynamic) continue;
            Transform pose = tracks.pose(object.name, f);
            pose.scale = object.transform.scale;
            surfaces.setPose(int(i), pose);
            if (scene.render.camera.followObject && *scene.render.camera.followObject == object.name) followed = pose;
        }
        surfaces.commit();
        const CloudVolume volume(density, scene.render.image, scene.render.sun.direction, &surfaces);
        frame.volume = volume.empty() ? nullptr : &volume;
        frame.camera = followed ? followCamera(scene.render.camera, *followed, surfaces, frame.width, frame.height)
                                : Camera::fromSettings(scene.render.camera, frame.width, frame.height);
        frame.frame = f;
        const RenderImage image = renderFrame(frame);
        for (const std::string& path : outputs) writeFrameImage(image, path);

        seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        ++summary.rendered;
        if (options.progress) options.progress(f, summary.rendered + summary.skipped, total, seconds);
    }
    summary.secondsPerFrame = summary.rendered > 0 ? seconds / summary.rendered : 0.0;
    return summary;
}

} // namespace vfield
