#pragma once
/// @file render_settings.h
/// How a scene is to be seen: camera, sun, sky and image settings, as typed
/// options parsed from the scene file. Right-handed, y up; the camera looks
/// from position towards lookAt with a vertical field of view in degrees.

#include <vfield/core/json.h>

#include <optional>
#include <string>

namespace vfield {

struct CameraSettings {
    Vec3d position{0.0, 50.0, 200.0}; ///< world units
    Vec3d lookAt{0.0, 0.0, 0.0};      ///< world point at the image centre
    Vec3d up{0.0, 1.0, 0.0};
    double fovDegrees = 45.0; ///< vertical field of view (0..180)
    /// Follow a dynamic object: the camera sits at the object's position plus
    /// offset, given in the object's heading frame (x forward, y up, z right:
    /// -x is behind it), and looks at the object; it moves in front of any
    /// surface between itself and the object.
    std::optional<std::string> followObject;
    Vec3d followOffset{-30.0, 10.0, 0.0};
};

struct SunSettings {
    Vec3d direction{0.4, 0.8, 0.3}; ///< towards the sun (normalized on use)
    Vec3d color{1.0, 0.96, 0.9};    ///< linear RGB
    double intensity = 3.0;         ///< radiance scale of the sun's light
};

struct SkySettings {
    Vec3d zenithColor{0.12, 0.28, 0.75}; ///< linear RGB
    Vec3d horizonColor{0.55, 0.68, 0.9}; ///< linear RGB
    double intensity = 1.0;
};

struct ImageSettings {
    int width = 640, height = 360; ///< pixels
    int samplesPerPixel = 4;
    double volumeStep = 0.5; ///< ray-march step in the volume, world units
    double extinction = 1.0; ///< sigma_t per unit density, 1 / world units
    double albedo = 0.9;     ///< scattering / extinction (0..1)
    double anisotropy = 0.3; ///< Henyey-Greenstein g (-1..1)
    /// March only through OpenVDB nodes holding density (VolumeRayIntersector)
    /// instead of across the cloud's whole box.
    bool skipEmptySpace = true;
};

struct RenderSettings {
    CameraSettings camera;
    SunSettings sun;
    SkySettings sky;
    ImageSettings image;
};

CameraSettings cameraSettingsFromJson(const JsonValue& json);
SunSettings sunSettingsFromJson(const JsonValue& json);
SkySettings skySettingsFromJson(const JsonValue& json);
ImageSettings imageSettingsFromJson(const JsonValue& json);

} // namespace vfield
