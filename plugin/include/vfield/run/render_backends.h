#pragma once
/// @file render_backends.h
/// The back-ends a render run picks by name (render/render_backend.h):
///   embree   vfield's own renderer (Embree surfaces, OpenVDB cloud)
///   povray   POV-Ray 3.7
///   both     the two side by side (OUT/embree/, OUT/povray/, OUT/frame.####.png)
/// A new back-end is its own class under render/ and one entry here.

#include <vfield/render/embree/surfaces.h>
#include <vfield/render/materials.h>
#include <vfield/render/render_backend.h>
#include <vfield/scene/scene.h>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace vfield {

/// What a run hands every back-end it makes.
struct BackendInputs {
    const Scene* scene = nullptr;
    const std::vector<TriangleMesh>* meshes = nullptr;         ///< per scene object, object space
    const std::map<int, SurfaceMaterial>* materials = nullptr; ///< per scene object
    /// The run's Embree scene of every surface, dynamic objects placed by the
    /// run each frame (it also places a following camera and shadows the cloud).
    const SurfaceScene* surfaces = nullptr;
    double terrainLow = 0.0, terrainHigh = 1.0; ///< heights the terrain's colours span
    std::string outputDir;
    std::vector<std::string> formats{"png"};
};

/// The names a run takes, in the order help lists them.
std::vector<std::string> renderBackendNames();

/// Makes the back-end of that name. Throws ValueError for an unknown name or
/// settings it refuses.
std::unique_ptr<RenderBackend> makeRenderBackend(const std::string& name, const BackendInputs& setup);

} // namespace vfield
