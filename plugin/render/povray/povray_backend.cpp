#include <vfield/render/povray/povray_backend.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/frame_file.h>
#include <vfield/render/povray/povray_runner.h>

#include <filesystem>

namespace fs = std::filesystem;

namespace vfield {

namespace {

constexpr const char* kMeshInclude = "meshes.inc";

} // namespace

PovrayBackend::PovrayBackend(const std::vector<PovrayMesh>& meshes, double terrainLow, double terrainHigh,
                             const RenderSettings& settings, const PovrayBackendOptions& options)
    : mSettings(settings), mOptions(options)
{
    for (const PovrayMesh& mesh : meshes)
        if (mesh.placement) mStaticObjects.push_back(mesh.object);
    writeTextAtomically((fs::path(mOptions.workFolder) / kMeshInclude).string(),
                        povrayMeshesText(meshes, terrainLow, terrainHigh));
}

PovrayBackend::~PovrayBackend()
{
    if (mOptions.keepScene) return;
    std::error_code ignored; // a folder still holding files (a failed frame's) stays
    fs::remove(fs::path(mOptions.workFolder) / kMeshInclude, ignored);
    fs::remove(mOptions.workFolder, ignored);
}

void PovrayBackend::render(int frame, const Camera& camera, const std::map<int, Transform>& poses, const CloudLighting& cloud,
                           const std::string& imagePath)
{
    PovrayFrame pov;
    pov.settings = &mSettings;
    pov.camera = camera;
    pov.frame = frame;
    pov.meshInclude = kMeshInclude;
    pov.staticObjects = mStaticObjects;
    pov.dynamicPoses = poses;
    const std::string df3 = frameFileName("density", frame, "df3"), skyLitDf3 = frameFileName("sky_lit", frame, "df3"),
                      scene = frameFileName("frame", frame, "pov"), rendered = frameFileName("render", frame, "png");
    const fs::path folder(mOptions.workFolder);
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
        runPovray(mOptions.workFolder, scene, rendered, mSettings.image, mSettings.povrayQuality, mOptions.threads);
    } catch (...) {
        mOptions.keepScene = true; // a failed frame's scene files and log stay for inspection
        throw;
    }
    fs::create_directories(fs::path(imagePath).parent_path());
    fs::rename(folder / rendered, imagePath);
    if (!mOptions.keepScene)
        for (const std::string& file : {df3, skyLitDf3, scene, rendered + ".log"}) fs::remove(folder / file);
}

} // namespace vfield
