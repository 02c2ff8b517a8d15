#include <vfield/render/embree/embree_backend.h>

#include <vfield/core/error.h>
#include <vfield/core/frame_file.h>
#include <vfield/render/embree/renderer.h>
#include <vfield/render/frame_image.h>

#include <chrono>
#include <filesystem>

namespace vfield {

EmbreeBackend::EmbreeBackend(const RenderSettings& settings, const SurfaceScene& surfaces,
                             std::map<int, SurfaceMaterial> materials, double terrainLow, double terrainHigh,
                             std::vector<std::string> formats)
    : mSettings(settings), mSurfaces(surfaces), mMaterials(std::move(materials)), mTerrainLow(terrainLow),
      mTerrainHigh(terrainHigh), mFormats(std::move(formats))
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

void EmbreeBackend::render(const FrameView& view, const std::string& out)
{
    const auto start = std::chrono::steady_clock::now();
    const CloudVolume volume(*view.cloud, mSettings.medium, mSettings.integrator);
    FrameToRender frame;
    frame.settings = &mSettings;
    frame.surfaces = &mSurfaces;
    frame.materials = mMaterials;
    frame.volume = volume.empty() ? nullptr : &volume;
    frame.camera = view.camera;
    frame.frame = view.frame;
    frame.terrainLow = mTerrainLow;
    frame.terrainHigh = mTerrainHigh;
    const RenderImage image = renderFrame(frame);
    for (const std::string& path : frameFiles(out, view.frame)) writeFrameImage(image, path);
    mSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

} // namespace vfield
