#include <vfield/render/embree/embree_backend.h>

#include <vfield/core/error.h>
#include <vfield/core/frame_file.h>
#include <vfield/render/embree/renderer.h>
#include <vfield/render/frame_image.h>

#include <embree3/rtcore.h>

#include <algorithm>
#include <chrono>
#include <filesystem>

namespace vfield {

EmbreeBackend::EmbreeBackend(const RenderSettings& settings, const SurfaceScene& surfaces,
                             std::map<int, SurfaceMaterial> materials, double terrainLow, double terrainHigh,
                             std::vector<std::string> formats, std::vector<std::string> objectNames)
    : mSettings(settings), mSurfaces(surfaces), mMaterials(std::move(materials)), mTerrainLow(terrainLow),
      mTerrainHigh(terrainHigh), mFormats(std::move(formats)), mObjectNames(std::move(objectNames)), mView(settings.view)
{
    for (const std::string& format : mFormats)
        if (format != "png" && format != "exr") throw ValueError("unknown image format '" + format + "' (png or exr)");
}

std::vector<std::string> EmbreeBackend::frameFiles(const std::string& out, int frame) const
{
    std::vector<std::string> files;
    for (const std::string& format : mFormats)
        files.push_back((std::filesystem::path(out) / frameFileName("frame", frame, format)).string());
    return files;
}

FrameToRender EmbreeBackend::frameToRender(const FrameView& view, const CloudVolume& volume) const
{
    FrameToRender frame;
    frame.settings = view.settings;
    frame.surfaces = &mSurfaces;
    frame.materials = mMaterials;
    frame.volume = volume.empty() ? nullptr : &volume;
    frame.camera = view.openingCamera.value_or(view.camera);
    frame.closingCamera = view.closingCamera;
    frame.motion = view.motion;
    frame.velocity = view.velocity;
    frame.secondsPerFrame = view.secondsPerFrame;
    frame.screenMotion = view.screenMotion;
    frame.frame = view.frame;
    frame.terrainLow = mTerrainLow;
    frame.terrainHigh = mTerrainHigh;
    frame.progress = view.progress;
    // Only EXR frames hold them.
    frame.passes = mSettings.image.passes && std::find(mFormats.begin(), mFormats.end(), "exr") != mFormats.end();
    return frame;
}

int EmbreeBackend::framesAround() const
{
    const IntegratorSettings& integrator = mSettings.integrator;
    const bool paths =
        integrator.kind == IntegratorKind::Fast && integrator.multipleScattering.method == MultipleScatteringMethod::Paths;
    return paths ? integrator.multipleScattering.pathFramesAround : 0;
}

void EmbreeBackend::look(const FrameView& view)
{
    auto volume = std::make_unique<CloudVolume>(*view.cloud, mSettings.medium, mSettings.integrator);
    const FrameToRender frame = frameToRender(view, *volume);
    mPaths[view.frame] = frame.volume ? traceScatteredPaths(frame) : ScatteredPaths{view.frame, {}};
    mLookedVolumes[view.frame] = std::move(volume);
}

void EmbreeBackend::render(const FrameView& view, const std::string& out)
{
    const auto start = std::chrono::steady_clock::now();
    // The cloud as a look at the frame made it, unless its motion reaches further.
    std::unique_ptr<CloudVolume> volume;
    if (const auto looked = mLookedVolumes.find(view.frame); looked != mLookedVolumes.end() && !view.motion)
        volume = std::move(looked->second);
    mLookedVolumes.erase(mLookedVolumes.begin(), mLookedVolumes.upper_bound(view.frame));
    if (!volume)
        volume = std::make_unique<CloudVolume>(*view.cloud, mSettings.medium, mSettings.integrator,
                                               view.motion ? view.motion->reach() : 0.0);
    FrameToRender frame = frameToRender(view, *volume);
    if (framesAround() > 0 && frame.volume) {
        mPaths.erase(mPaths.begin(), mPaths.lower_bound(view.lightFrom));
        if (mPaths.count(view.frame) == 0) mPaths[view.frame] = traceScatteredPaths(frame);
        for (const auto& [at, paths] : mPaths)
            if (at <= view.lightTo) frame.scatteredPaths.push_back(&paths);
    }
    RenderImage image = renderFrame(frame);
    image.passes.objectNames = mObjectNames;
    for (const std::string& path : frameFiles(out, view.frame)) writeFrameImage(image, path, mView, mSettings.image.exrDepth);
    mSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string embreeVersion()
{
    RTCDevice device = rtcNewDevice(nullptr);
    if (!device) throw Error("Embree could not create a device");
    // Embree packs its version as major * 10000 + minor * 100 + patch.
    const ssize_t packed = rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION);
    rtcReleaseDevice(device);
    return std::to_string(packed / 10000) + "." + std::to_string(packed / 100 % 100) + "." + std::to_string(packed % 100);
}

} // namespace vfield
