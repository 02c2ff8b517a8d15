#pragma once
/// @file povray_backend.h
/// Frames through POV-Ray 3.7, as a RenderBackend: the scene's meshes written
/// once into a shared include in a work folder; per frame a .pov scene and the
/// cloud's df3 files beside it, POV-Ray run on them (povray_runner.h), and
/// its image moved to OUT/frame.####.png. Scene files are removed after each
/// frame unless kept; a failed frame always keeps its files and log for
/// inspection. POV-Ray scatters once, with the phase's forward lobe, and
/// draws no haze: cannotDraw() says so for the settings that ask for more.

#include <vfield/render/cloud_lighting.h>
#include <vfield/render/display_view.h>
#include <vfield/render/povray/povray_scene.h>
#include <vfield/render/povray/povray_settings.h>
#include <vfield/render/render_backend.h>

#include <string>
#include <vector>

namespace vfield {

class PovrayBackend : public RenderBackend {
public:
    /// settings (image size and samples, sun, sky, medium, integrator) and
    /// the meshes must outlive the back-end; povray.threads 0 stands for
    /// `threads`. Scene files are written into workFolder, and kept there
    /// with povray.keepScene. Throws ValueError for settings it cannot honour at all
    /// (a transparent sky), and FileError when POV-Ray is not installed.
    PovrayBackend(std::vector<PovrayMesh> meshes, double terrainLow, double terrainHigh, const RenderSettings& settings,
                  const PovraySettings& povray, std::string workFolder, int threads);
    ~PovrayBackend() override;
    PovrayBackend(const PovrayBackend&) = delete;
    PovrayBackend& operator=(const PovrayBackend&) = delete;

    std::string name() const override { return "povray"; }
    std::vector<std::string> cannotDraw(const RenderSettings& settings) const override;
    std::vector<std::string> frameFiles(const std::string& out, int frame) const override;
    /// Writes the meshes' include into the work folder.
    void prepare() override;
    /// Static meshes where the include placed them, dynamic ones at the
    /// frame's poses (with their scale), the lit cloud.
    void render(const FrameView& frame, const std::string& out) override;

private:
    std::vector<PovrayMesh> mMeshes;
    double mTerrainLow, mTerrainHigh;
    const RenderSettings& mSettings;
    PovraySettings mPovray;
    std::string mWorkFolder;
    bool mKeepScene;
    DisplayView mView;
    std::vector<int> mStaticObjects;
    bool mPrepared = false;
};

} // namespace vfield
