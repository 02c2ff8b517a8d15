#pragma once
/// @file povray_scene.h
/// A frame as a self-contained POV-Ray 3.7 scene: camera, sun, sky, meshes
/// (mesh2, written once into a shared include) and the cloud (interior media
/// of a hollow box whose density is a df3 file). Scattering, absorption and
/// lighting follow vfield's own renderer so the two back-ends check each other.
///
/// Conventions. vfield is right-handed with y up; POV-Ray is left-handed with
/// y up. Every point and direction is written mirrored in z, (x, y, -z), and the
/// camera's right vector is mirrored with it, so POV-Ray shows the same picture.
///
/// Lighting. The sun is a parallel light of colour sunRadiance / pi (POV-Ray's
/// Lambert term has no 1/pi); the sky's light on surfaces, which vfield makes
/// grow from sideways to upward-facing normals, is an ambient term plus a
/// shadowless light from straight above, matching it at both ends. The cloud's
/// sky light is emission of a second medium whose density is the cloud's
/// density x the sky's transmittance down to it (CloudVolume::skyLitDensity),
/// times sigma_s and the sky's mean radiance, since POV-Ray media see only
/// light sources. The sky
/// sphere is the horizon-to-zenith gradient without the sun's glow.

#include <vfield/render/camera.h>
#include <vfield/render/materials.h>
#include <vfield/render/povray/df3.h>
#include <vfield/render/povray/povray_settings.h>

#include <vfield/core/transform.h>
#include <vfield/mesh/triangle_mesh.h>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace vfield {

struct PovrayMesh {
    int object = -1; ///< declared as VF_Object_<object>
    const TriangleMesh* mesh = nullptr;
    SurfaceMaterial material;
    /// Static meshes are written in world space (placement x mesh); dynamic
    /// ones (no placement) in object space, placed by each frame.
    std::optional<Transform> placement;
};

/// The shared include: one mesh2 per mesh, with per-point normals and, for
/// terrain, per-point albedo (heights coloured within [terrainLow, terrainHigh]).
std::string povrayMeshesText(const std::vector<PovrayMesh>& meshes, double terrainLow, double terrainHigh);

struct PovrayCloud {
    std::string df3File; ///< the density, relative to the scene file's folder
    Df3Placement placement;
    std::string skyLitDf3File; ///< density x sky transmittance, on the same cells
    Df3Placement skyLitPlacement;
};

struct PovrayFrame {
    const RenderSettings* settings = nullptr;     ///< sun, sky, medium; media samples from the integrator's volumeStep
    PovrayQuality quality = PovrayQuality::Final; ///< preview takes fewer media samples
    Camera camera{Vec3d(0, 0, 1), Vec3d(0.0), Vec3d(0, 1, 0), 45, 1, 1};
    int frame = 0;
    std::string meshInclude;               ///< povrayMeshesText's file, relative to the scene file
    std::vector<int> staticObjects;        ///< shown where the include placed them
    std::map<int, Transform> dynamicPoses; ///< dynamic objects, with their scale
    std::optional<PovrayCloud> cloud;      ///< none: no volume this frame
};

/// The frame's .pov text (it includes meshInclude and reads the df3 file).
std::string povrayFrameText(const PovrayFrame& frame);

} // namespace vfield
