#pragma once
/// @file render_settings.h
/// How a scene is to be seen, as typed options parsed from the scene file:
/// camera, sun and sky; the image (its size and samples); the cloud as a
/// medium; and how the volume is integrated. Right-handed, y up; the camera
/// looks from position towards lookAt with a vertical field of view in degrees.
/// Every back-end reads these, and only these: command-line overrides
/// (--resolution, --spp) are applied to a copy of them before rendering.

#include <vfield/core/json.h>

#include <optional>
#include <string>

namespace vfield {

/// Henyey-Greenstein phase function for the cosine between the directions of
/// propagation before and after scattering; integrates to 1 over the sphere.
double henyeyGreenstein(double cosTheta, double g);

struct CameraSettings {
    Vec3d position{0.0, 50.0, 200.0}; ///< world units
    Vec3d lookAt{0.0, 0.0, 0.0};      ///< world point at the image centre
    Vec3d up{0.0, 1.0, 0.0};          ///< non-zero
    double fovDegrees = 45.0;         ///< vertical field of view (1e-3..179)
    /// Follow a dynamic object, looking at it from offset (world units; x
    /// forward, y up, z right): -x along the path it flew and y above, or, for
    /// x >= 0, in its heading frame; in front of any surface between the two
    /// (followCamera() in camera.h).
    std::optional<std::string> followObject;
    Vec3d followOffset{-30.0, 10.0, 0.0};

    /// Throws OptionError naming the first option out of range.
    void validate() const;
};

struct SunSettings {
    Vec3d direction{0.4, 0.8, 0.3}; ///< towards the sun (non-zero; normalized on use)
    Vec3d color{1.0, 0.96, 0.9};    ///< linear RGB, >= 0
    double intensity = 3.0;         ///< radiance scale of the sun's light (0..1e6)

    void validate() const;
};

struct SkySettings {
    Vec3d zenithColor{0.12, 0.28, 0.75}; ///< linear RGB, >= 0
    Vec3d horizonColor{0.55, 0.68, 0.9}; ///< linear RGB, >= 0
    double intensity = 1.0;              ///< (0..1e6)
    /// Aerial perspective: the distance over which haze of the horizon's
    /// colour covers what is seen, world units (0..1e12); 0: clear air.
    /// What lies at distance d keeps e^(-d / hazeDistance) of its light.
    double hazeDistance = 0.0;

    void validate() const;
};

/// The picture: its size and how many samples each pixel averages.
struct ImageSettings {
    static constexpr int kMaxResolution = 16384; ///< pixels along either side

    int width = 640, height = 360; ///< pixels (1..kMaxResolution)
    int samplesPerPixel = 4;       ///< (1..65536)
    /// The sky drawn as RGB 0, alpha 0, for compositing over a plate; by
    /// default it is drawn, opaque (alpha 1). Frames are premultiplied either way.
    bool transparentSky = false;

    /// Keys as in a scene file's "render": "resolution/0", "samplesPerPixel".
    void validate() const;
};

/// The cloud as a participating medium: density x extinction is sigma_t.
/// Its phase function is two Henyey-Greenstein lobes,
///   p = (1 - backWeight) HG(anisotropy) + backWeight HG(backAnisotropy):
/// a strong forward lobe gives the silver lining of a cloud seen towards the
/// sun, the backward lobe its brightness seen with the sun behind.
struct MediumSettings {
    double extinction = 1.0;      ///< sigma_t per unit density, 1 / world units (0..1e9)
    double albedo = 0.9;          ///< scattering / extinction (0..1)
    double anisotropy = 0.3;      ///< the forward lobe's g (-0.99..0.99)
    double backAnisotropy = -0.3; ///< the backward lobe's g (-0.99..0.99)
    double backWeight = 0.0;      ///< the backward lobe's share (0..1); 0: one lobe

    /// The phase function for the cosine between the directions of
    /// propagation before and after scattering; integrates to 1 over the sphere.
    double phase(double cosTheta) const;
    void validate() const;
};

/// Light scattered more than once, approximated by octaves (after Wrenninge
/// et al., "Production Volume Rendering", SIGGRAPH 2017 course). Octave 0 is
/// single scattering: the light seen through transmittance T. Octave i >= 1
/// gives back a^i of what the cloud took from the light, T^(b^i) - T, with
/// c^i of the phase's eccentricity: nothing where the cloud is thin, much deep
/// inside it. The defaults are fitted to the reference path tracer (a sphere
/// of cloud lit from the side, a box lit from above: mean radiance within
/// 10%; tests/reference_integrator_test.cpp).
struct MultipleScattering {
    int octaves = 4;                   ///< (1..8)
    double scatteringFalloff = 0.8;    ///< a, for the sun (0..1)
    double extinctionFalloff = 0.3;    ///< b (0..1)
    double eccentricityFalloff = 0.5;  ///< c (0..1)
    double skyScatteringFalloff = 0.5; ///< a for the light of the sky and the ground, diffuse already (0..1)

    void validate() const;
};

/// Which light transport a picture is made with.
enum class IntegratorKind {
    /// A ray march with precomputed light grids and multiple scattering by
    /// octaves: fast, noise-free, approximate.
    Fast,
    /// An unbiased volumetric path tracer (delta and ratio tracking through
    /// the density, diffuse bounces off surfaces): slow, noisy, converges to
    /// the scene's true light as samples grow. What Fast is measured against.
    Reference
};

/// How a ray integrates the medium.
struct IntegratorSettings {
    IntegratorKind kind = IntegratorKind::Fast;
    /// Reference: scattering or reflection events a path may have (1..1e6);
    /// 1 is single scattering. Paths also end by Russian roulette after three.
    int maxBounces = 1000;
    double volumeStep = 0.5; ///< Fast: ray-march step in the volume, world units (1e-6..1e9)
    /// March only through OpenVDB nodes holding density (VolumeRayIntersector)
    /// instead of across the cloud's whole box.
    bool skipEmptySpace = true;
    MultipleScattering multipleScattering;

    void validate() const;
};

/// How the POV-Ray back-end trades time for quality.
enum class PovrayQuality {
    /// Every pixel supersampled on an unjittered n x n grid (samplesPerPixel =
    /// n^2), media sampled at every volumeStep: what the golden images take.
    Final,
    /// Antialiasing where a pixel differs from its neighbours by more than
    /// 0.3 only (2 x 2, one level deep), a quarter of the media samples
    /// (at least 8): for previews and farm dailies.
    Preview
};

struct RenderSettings {
    CameraSettings camera;
    SunSettings sun;
    SkySettings sky;
    ImageSettings image;
    MediumSettings medium;
    IntegratorSettings integrator;
    PovrayQuality povrayQuality = PovrayQuality::Final;

    /// Checks every part; keys as in a scene file ("camera/fovDegrees",
    /// "render/resolution/0", "render/albedo", ...). Throws OptionError.
    void validate() const;
};

CameraSettings cameraSettingsFromJson(const JsonValue& json);
SunSettings sunSettingsFromJson(const JsonValue& json);
SkySettings skySettingsFromJson(const JsonValue& json);
/// The scene file's "render" object: the image, the medium and the integrator.
void renderSectionFromJson(const JsonValue& json, RenderSettings& settings);

} // namespace vfield
