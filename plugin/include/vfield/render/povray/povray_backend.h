#pragma once
/// @file povray_backend.h
/// Frames through POV-Ray 3.7: the scene's meshes written once into a shared
/// include in a work folder; per frame a .pov scene and the cloud's df3 files
/// beside it, POV-Ray run on them (povray_runner.h), and its image moved to
/// where the caller wants it. Scene files are removed after each frame unless
/// kept; a failed frame always keeps its files and log for inspection.

#include <vfield/render/cloud_lighting.h>
#include <vfield/render/povray/povray_scene.h>

#include <string>
#include <vector>

namespace vfield {

struct PovrayBackendOptions {
    std::string workFolder; ///< where scene files are written (OUT/povray-scene/)
    bool keepScene = false; ///< keep the .pov, .inc and .df3 files
    int threads = 1;        ///< POV-Ray's render threads (1: reproducible media noise)
};

class PovrayBackend {
public:
    /// Writes the meshes' include into the work folder. settings (image size
    /// and samples, sun, sky, medium, integrator) must outlive the back-end.
    PovrayBackend(const std::vector<PovrayMesh>& meshes, double terrainLow, double terrainHigh, const RenderSettings& settings,
                  const PovrayBackendOptions& options);
    ~PovrayBackend();
    PovrayBackend(const PovrayBackend&) = delete;
    PovrayBackend& operator=(const PovrayBackend&) = delete;

    /// Renders one frame to imagePath (PNG): static meshes where the include
    /// placed them, dynamic ones at poses (with their scale), the lit cloud.
    void render(int frame, const Camera& camera, const std::map<int, Transform>& poses, const CloudLighting& cloud,
                const std::string& imagePath);

private:
    const RenderSettings& mSettings;
    PovrayBackendOptions mOptions;
    std::vector<int> mStaticObjects;
};

} // namespace vfield
