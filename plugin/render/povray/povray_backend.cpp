#include <vfield/render/povray/povray_backend.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>
#include <vfield/core/field_visitors.h>
#include <vfield/core/frame_file.h>
#include <vfield/core/image_file.h>
#include <vfield/render/frame_image.h>
#include <vfield/render/povray/povray_runner.h>

#include <chrono>
#include <filesystem>

namespace fs = std::filesystem;

namespace vfield {

namespace {

constexpr const char* kMeshInclude = "meshes.inc";

} // namespace

void PovraySettings::validate() const { checkFields(*this); }

PovrayBackend::PovrayBackend(std::vector<PovrayMesh> meshes, double terrainLow, double terrainHigh,
                             const RenderSettings& settings, const PovraySettings& povray, std::string workFolder, int threads)
    : mMeshes(std::move(meshes)), mTerrainLow(terrainLow), mTerrainHigh(terrainHigh), mSettings(settings), mPovray(povray),
      mWorkFolder(std::move(workFolder)), mKeepScene(povray.keepScene), mView(settings.view)
{
    if (mPovray.threads == 0) mPovray.threads = threads;
    if (settings.image.transparentSky)
        throw ValueError("a transparent sky is for EXR frames of the Embree back-end; the POV-Ray back-end draws the sky");
    requirePovray();
    for (const PovrayMesh& mesh : mMeshes)
        if (mesh.placement) mStaticObjects.push_back(mesh.object);
}

PovrayBackend::~PovrayBackend()
{
    if (!mPrepared || mKeepScene) return;
    std::error_code ignored; // a folder still holding files (a failed frame's) stays
    fs::remove(fs::path(mWorkFolder) / kMeshInclude, ignored);
    fs::remove(mWorkFolder, ignored);
}

std::vector<std::string> PovrayBackend::cannotDraw(const RenderSettings& s) const
{
    std::vector<std::string> lines;
    if (s.sky.hazeDistance > 0.0) lines.push_back("povray cannot draw haze (sky.hazeDistance): its frames show clear air");
    if (s.image.seesMotion())
        lines.push_back("povray cannot draw motion blur (render.shutter): its frames show the frame's instant");
    if (s.medium.backWeight > 0.0)
        lines.push_back(
            "povray cannot draw the phase's backward lobe (render.backWeight): it scatters with the forward lobe only");
    if (s.integrator.multipleScattering.octaves > 1 || s.integrator.multipleScattering.method == MultipleScatteringMethod::Paths)
        lines.push_back("povray cannot draw light scattered more than once (render.multipleScattering): its media scatter once");
    if (s.integrator.kind == IntegratorKind::Reference)
        lines.push_back(
            "povray cannot draw with the reference path tracer (render.integrator): it samples its media its own way");
    return lines;
}

std::vector<std::string> PovrayBackend::frameFiles(const std::string& out, int frame) const
{
    return {(fs::path(out) / frameFileName("frame", frame, "png")).string()};
}

void PovrayBackend::prepare()
{
    writeTextAtomically((fs::path(mWorkFolder) / kMeshInclude).string(), povrayMeshesText(mMeshes, mTerrainLow, mTerrainHigh));
    mPrepared = true;
}

void PovrayBackend::render(const FrameView& view, const std::string& out)
{
    const auto start = std::chrono::steady_clock::now();
    const CloudLighting& cloud = *view.cloud;
    PovrayFrame pov;
    pov.settings = view.settings;
    pov.quality = mPovray.quality;
    pov.camera = view.camera;
    pov.frame = view.frame;
    pov.meshInclude = kMeshInclude;
    pov.staticObjects = mStaticObjects;
    pov.dynamicPoses = view.poses;
    const std::string df3 = frameFileName("density", view.frame, "df3"), skyLitDf3 = frameFileName("sky_lit", view.frame, "df3"),
                      scene = frameFileName("frame", view.frame, "pov"), rendered = frameFileName("render", view.frame, "exr");
    const fs::path folder(mWorkFolder);
    if (!cloud.density().empty()) {
        PovrayCloud medium;
        medium.df3File = df3;
        medium.placement = writeDf3(cloud.density(), (folder / df3).string());
        medium.skyLitDf3File = skyLitDf3;
        medium.skyLitPlacement = writeDf3(*cloud.skyLitDensity(), (folder / skyLitDf3).string());
        pov.cloud = medium;
    }
    writeTextAtomically((folder / scene).string(), povrayFrameText(pov));
    try {
        runPovray(mWorkFolder, scene, rendered, mSettings.image, mPovray.quality, mPovray.threads, view.progress);
    } catch (...) {
        mKeepScene = true; // a failed frame's scene files and log stay for inspection
        throw;
    }
    // POV-Ray's scene-linear light, shown through the same view as vfield's own frames.
    const std::string image = frameFiles(out, view.frame).front();
    fs::create_directories(fs::path(image).parent_path());
    writeImage(toDisplay(readImageAsFloat((folder / rendered).string()), mView), image);
    fs::remove(folder / rendered);
    if (!mKeepScene)
        for (const std::string& file : {df3, skyLitDf3, scene, rendered + ".log"}) fs::remove(folder / file);
    mSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

} // namespace vfield
