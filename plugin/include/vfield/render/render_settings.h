#pragma once
/// @file render_settings.h
/// How a scene is to be seen, as typed options parsed from the scene file:
/// camera, sun and sky; the image (its size and samples); the cloud as a
/// medium; and how the volume is integrated. Right-handed, y up; the camera
/// looks from position towards lookAt with a vertical field of view in degrees.
/// Every back-end reads these, and only these: command-line overrides
/// (--resolution, --spp) are applied to a copy of them before rendering.

#include <vfield/core/animation.h>
#include <vfield/core/fields.h>
#include <vfield/render/pixel_filter.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace vfield {

/// Henyey-Greenstein phase function for the cosine between the directions of
/// propagation before and after scattering; integrates to 1 over the sphere.
double henyeyGreenstein(double cosTheta, double g);

/// A camera that follows a dynamic object, looking at it from offset (world
/// units; x forward, y up, z right): -x along the path it flew and y above,
/// or, for x >= 0, in its heading frame; in front of any surface between the
/// two (followCamera() in camera.h).
struct CameraFollowSettings {
    std::string object;
    Vec3d offset{-30.0, 10.0, 0.0};

    void validate() const {}

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("object", self.object).required().doc("the dynamic object followed"));
        visit(field("offset", self.offset)
                  .unit("world units")
                  .doc("x forward, y up, z right: with x < 0 the camera rides the object's own path, -x units of path "
                       "length back, raised by y; with x >= 0 the offset is in the object's heading frame"));
    }
};

/// A camera travelling a path through points at constant speed
/// (camera_path.h), from the first point at frame `start` to the last at
/// `end`, looking ahead along it or at the camera's lookAt.
struct CameraPathSettings {
    std::vector<Vec3d> points;
    double start = 1.0, end = 120.0;
    bool lookAlong = false;

    /// Throws OptionError naming the first option out of range.
    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("points", self.points)
                  .required()
                  .unit("world units")
                  .doc("the path passes through these, in order: at least two, no two in a row equal"));
        visit(field("start", self.start).unit("frames").doc("when the camera is at the first point (before it: there)"));
        visit(field("end", self.end).unit("frames").doc("when it reaches the last (after it: there); after start"));
        visit(field("lookAlong", self.lookAlong)
                  .doc("look ahead along the path; off, the camera looks at lookAt (which may be keyed)"));
    }
};

struct CameraSettings {
    Vec3d position{0.0, 50.0, 200.0};
    Vec3d lookAt{0.0, 0.0, 0.0};
    Vec3d up{0.0, 1.0, 0.0};
    double fovDegrees = 45.0;
    std::optional<CameraFollowSettings> follow;
    std::optional<CameraPathSettings> path;
    Animation animation;

    /// Throws OptionError naming the first option out of range.
    void validate() const;
    /// The camera at frame (fractional): its keyed values there, placed on its
    /// path; a camera that stands there (no keys, no path).
    CameraSettings at(double frame) const;
    /// Whether it moves or changes over the frames by itself (keys, a path).
    bool moves() const { return path.has_value() || !animation.empty(); }

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("position", self.position).animatable(self.animation).unit("world units").doc("the pinhole"));
        visit(field("lookAt", self.lookAt).animatable(self.animation).unit("world units").doc("the point at the image's centre"));
        visit(field("up", self.up).isDirection().animatable(self.animation).doc("what is up in the image"));
        visit(field("fovDegrees", self.fovDegrees)
                  .animatable(self.animation)
                  .range(1e-3, 179)
                  .unit("degrees")
                  .doc("vertical field of view"));
        visit(field("follow", self.follow)
                  .doc("follow a dynamic object, moved in front of any surface between camera and object; position and "
                       "lookAt are then unused"));
        visit(field("path", self.path)
                  .doc("travel a path at constant speed; position (and with lookAlong, lookAt) are then unused"));
    }
};

struct SunSettings {
    Vec3d direction{0.4, 0.8, 0.3}; ///< normalized on use
    Vec3d color{1.0, 0.96, 0.9};
    double intensity = 3.0;
    Animation animation;

    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("direction", self.direction).isDirection().animatable(self.animation).doc("towards the sun"));
        visit(field("color", self.color).animatable(self.animation).atLeast(0).unit("linear RGB").doc("the sun's colour"));
        visit(field("intensity", self.intensity)
                  .animatable(self.animation)
                  .range(0, 1e6)
                  .doc("radiance scale of the sun's light (irradiance, as Blender's sun strength)"));
    }
};

struct SkySettings {
    Vec3d zenithColor{0.12, 0.28, 0.75};
    Vec3d horizonColor{0.55, 0.68, 0.9};
    double intensity = 1.0;
    double hazeDistance = 0.0;
    Animation animation;

    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("zenithColor", self.zenithColor)
                  .animatable(self.animation)
                  .atLeast(0)
                  .unit("linear RGB")
                  .doc("the sky straight up"));
        visit(field("horizonColor", self.horizonColor)
                  .animatable(self.animation)
                  .atLeast(0)
                  .unit("linear RGB")
                  .doc("the sky at the horizon, and the haze"));
        visit(field("intensity", self.intensity)
                  .animatable(self.animation)
                  .range(0, 1e6)
                  .doc("scale of the sky's light; it also lights surfaces and the cloud"));
        visit(field("hazeDistance", self.hazeDistance)
                  .animatable(self.animation)
                  .range(0, 1e12)
                  .unit("world units")
                  .doc("aerial perspective: what lies at distance d keeps e^(-d / hazeDistance) of its light; 0: clear air. "
                       "Embree back-end only"));
    }
};

/// The precision of an EXR frame's colours, alpha and passes (its depth is
/// always 32-bit), as Blender and Nuke offer it.
enum class ExrDepth {
    Half, ///< 16-bit floats: 11 bits of precision, half the size
    Float ///< 32-bit floats
};
inline constexpr EnumName<ExrDepth> kExrDepthNames[] = {{ExrDepth::Half, "half"}, {ExrDepth::Float, "float"}};
constexpr const auto& enumNames(ExrDepth) { return kExrDepthNames; }

/// The picture: its size and how many samples each pixel averages.
struct ImageSettings {
    static constexpr int kMaxResolution = 16384; ///< pixels along either side

    int width = 640, height = 360;
    int samplesPerPixel = 4;
    /// As POV-Ray's adaptive anti-aliasing does. The reference integrator
    /// takes every sample in every pixel whatever this is: deciding from a
    /// first sample would keep it from converging.
    double adaptiveThreshold = 0.0;
    /// 0: a box; otherwise a Gaussian this many pixels wide (PixelFilter).
    double pixelFilterWidth = 2.0;
    /// Off, the sky is drawn opaque (alpha 1); frames are premultiplied either way.
    bool transparentSky = false;
    int seed = 0;
    /// Off (as Blender's default), every frame draws the same random numbers:
    /// what does not move keeps its noise still instead of boiling.
    bool animatedSeed = false;
    /// EXR frames carry the render passes (RenderPasses) as layers beside the
    /// beauty; frames written only as PNG are rendered without them.
    bool passes = true;
    ExrDepth exrDepth = ExrDepth::Half;
    /// When the shutter opens and closes, in frames from the frame's instant
    /// (Blender's shutter of 0.5 is [-0.25, 0.25]). Open as long as it is
    /// closed, [t, t], the frame is the instant t frames from its own.
    double shutterOpen = 0.0, shutterClose = 0.0;

    /// Samples spread over an open shutter: motion blur.
    bool motionBlur() const { return shutterClose > shutterOpen; }
    /// The shutter sees more than the frame's instant, or another instant.
    bool seesMotion() const { return shutterOpen != 0.0 || shutterClose != 0.0; }

    /// The stream every random number of a frame is drawn from (with the pixel and sample).
    uint32_t noiseStream(int frame) const
    {
        return animatedSeed ? (uint32_t(frame) * 0x9e3779b9u) ^ uint32_t(seed) : uint32_t(seed);
    }

    /// Keys as in a scene file's "render": "resolution/0", "samplesPerPixel".
    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("resolution", pairOf(self.width, self.height, "width, height"))
                  .range(1, kMaxResolution)
                  .unit("pixels")
                  .doc("image size"));
        visit(field("samplesPerPixel", self.samplesPerPixel).range(1, 65536).doc("samples averaged per pixel"));
        visit(field("adaptiveThreshold", self.adaptiveThreshold)
                  .range(0, 1)
                  .doc("above 0, only the pixels whose first sample differs from a neighbour's by more than this "
                       "(sRGB colour, any channel, or coverage), or that the cloud covers by more than this, take all "
                       "samplesPerPixel, the others one; 0: every pixel takes them all. The reference integrator always "
                       "takes them all"));
        visit(field("pixelFilterWidth", self.pixelFilterWidth)
                  .range(0, PixelFilter::kMaxWidth)
                  .unit("pixels")
                  .doc("each sample's light is shared among the pixels whose centres lie within half this of it, by a "
                       "Gaussian (as Arnold's, RenderMan's and Mantra's default 2x2 one), so a pixel averages its "
                       "neighbours' nearby samples with its own and a cloud's fine detail does not boil from frame to "
                       "frame; 0: a box, each sample in its own pixel alone; else at least 1. Embree back-end only"));
        visit(field("transparentSky", self.transparentSky)
                  .doc("the sky drawn as RGB 0, alpha 0 in EXR frames (premultiplied), for compositing over a plate; "
                       "PNG frames then show black sky. Embree back-end only"));
        visit(field("seed", self.seed)
                  .range(0, 2147483647)
                  .doc("of the random numbers: another seed draws the same image with other noise. Embree back-end only"));
        visit(field("animatedSeed", self.animatedSeed)
                  .doc("draw each frame's noise afresh, as Blender's animated seed does; off, every frame draws the same "
                       "numbers and a shot where nothing moves renders identical frames. Embree back-end only"));
        visit(field("passes", self.passes)
                  .doc("EXR frames carry the render passes as layers beside the beauty (R, G, B, A, Z): cloud.RGBA, "
                       "surfaces.RGBA, shadow.X, normal.XYZ, objectIndex.X and the motion vectors vector.XYZW, named as Nuke and "
                       "Blender name multilayer EXR channels (docs/rendering.md). Embree back-end only"));
        visit(field("exrDepth", self.exrDepth)
                  .doc("the precision of EXR frames' colours, alpha and passes: half (16-bit floats, as Nuke and Blender "
                       "write by default) or float (32-bit); depth is always 32-bit"));
        visit(field("shutter", pairOf(self.shutterOpen, self.shutterClose, "open, close"))
                  .range(-1, 1)
                  .unit("frames")
                  .doc("when the shutter opens and closes, from the frame's instant: [-0.25, 0.25] blurs what moves "
                       "over half a frame (Blender's shutter 0.5), the cloud by its `vel` grid, dynamic objects and a "
                       "following camera by their tracks; [0, 0], the default, renders the instant. Embree back-end only"));
    }
};

/// How the picture's scene-linear light is shown on a display, as Blender's
/// colour management does: scaled by the exposure, then through a view of an
/// OpenColorIO config (vfield/render/display_view.h). PNG frames are what the
/// view shows; EXR frames keep the light as rendered.
struct ViewSettings {
    std::string view = "Filmic";
    double exposure = 0.0;

    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("view", self.view)
                  .doc("the OpenColorIO view of the sRGB display that PNG frames show: Filmic (highlights rolled off "
                       "towards white), Standard (clipped at 1), Raw, or a view of $OCIO's config when it is set"));
        visit(field("exposure", self.exposure)
                  .range(-32, 32)
                  .unit("stops")
                  .doc("the light scaled by 2^exposure before the view; EXR frames keep the light as rendered"));
    }
};

/// The cloud as a participating medium: density x extinction is sigma_t.
/// Its phase function is two Henyey-Greenstein lobes,
///   p = (1 - backWeight) HG(anisotropy) + backWeight HG(backAnisotropy):
/// a strong forward lobe gives the silver lining of a cloud seen towards the
/// sun, the backward lobe its brightness seen with the sun behind.
struct MediumSettings {
    double extinction = 1.0;
    double albedo = 0.9;
    double anisotropy = 0.3;
    double backAnisotropy = -0.3;
    double backWeight = 0.0; ///< 0: one lobe

    /// The phase function for the cosine between the directions of
    /// propagation before and after scattering; integrates to 1 over the sphere.
    double phase(double cosTheta) const;
    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("extinction", self.extinction).range(0, 1e9).unit("1/world units").doc("sigma_t per unit density"));
        visit(field("albedo", self.albedo).range(0, 1).doc("scattering / extinction"));
        visit(field("anisotropy", self.anisotropy).range(-0.99, 0.99).doc("the phase's forward Henyey-Greenstein lobe, g"));
        visit(field("backAnisotropy", self.backAnisotropy).range(-0.99, 0.99).doc("the backward lobe's g"));
        visit(field("backWeight", self.backWeight)
                  .range(0, 1)
                  .doc("the backward lobe's share w: p = (1 - w) HG(anisotropy) + w HG(backAnisotropy); the POV-Ray "
                       "back-end uses the forward lobe only"));
    }
};

/// Light scattered more than once, approximated by octaves (after Wrenninge
/// et al., "Production Volume Rendering", SIGGRAPH 2017 course). Octave 0 is
/// single scattering: the light seen through transmittance T. Octave i >= 1
/// gives back a^i of what the cloud took from the light, T^(b^i) - T, with
/// c^i of the phase's eccentricity: nothing where the cloud is thin, much deep
/// inside it. The defaults are fitted to the reference path tracer: a sphere
/// of cloud lit from the side and a box lit from above within 10%
/// (tests/render/reference_integrator_test.cpp), and a dense billowed cumulus
/// (scenes/features/cumulus.json) lit from behind the camera, the side and
/// the front within 10%.
///
/// Octaves place the light only on average: in a thick cloud the light that
/// enters, scatters many times and comes back out elsewhere is not where they
/// put it. `paths` computes it instead, once per frame, with the reference
/// path tracer's own camera paths, gathered on a lattice over the cloud
/// where they first scatter (path_tracer.h).
enum class MultipleScatteringMethod { Octaves, Paths };
inline constexpr EnumName<MultipleScatteringMethod> kMultipleScatteringMethodNames[] = {
    {MultipleScatteringMethod::Octaves, "octaves"}, {MultipleScatteringMethod::Paths, "paths"}};
constexpr const auto& enumNames(MultipleScatteringMethod) { return kMultipleScatteringMethodNames; }

struct MultipleScatteringSettings {
    MultipleScatteringMethod method = MultipleScatteringMethod::Octaves;
    int octaves = 4;
    double scatteringFalloff = 0.9;
    double extinctionFalloff = 0.3;
    double eccentricityFalloff = 0.25;
    double skyScatteringFalloff = 0.5; ///< its own a: that light is diffuse already
    double pathSpacing = 6.0;
    int pathsPerFrame = 50000;
    int pathFramesAround = 0;

    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("method", self.method)
                  .doc("octaves: the fast approximation below; paths: the reference path tracer's estimate of the light "
                       "scattered more than once, gathered on a lattice over the cloud, once per frame"));
        visit(field("octaves", self.octaves).range(1, 8).doc("octave 0 is single scattering; 1: single scattering only"));
        visit(field("scatteringFalloff", self.scatteringFalloff)
                  .range(0, 1)
                  .doc("a, for the sun: octave i gives back a^i of what the cloud took from the light"));
        visit(field("extinctionFalloff", self.extinctionFalloff).range(0, 1).doc("b: octave i sees transmittance T^(b^i)"));
        visit(field("eccentricityFalloff", self.eccentricityFalloff)
                  .range(0, 1)
                  .doc("c: octave i has c^i of the phase's eccentricity"));
        visit(field("skyScatteringFalloff", self.skyScatteringFalloff)
                  .range(0, 1)
                  .doc("a for the light of the sky and the ground"));
        visit(field("pathSpacing", self.pathSpacing)
                  .range(1, 64)
                  .unit("density voxels")
                  .doc("paths: the lattice's spacing; finer keeps more of the light's detail and needs more paths for the "
                       "same noise"));
        visit(field("pathsPerFrame", self.pathsPerFrame)
                  .range(1, 1e6)
                  .doc("paths: the reference's camera paths whose light, from where they first scatter in the cloud, the "
                       "lattice gathers (at most; fewer where the cloud covers less than a quarter of its box's part of "
                       "the image); the same at any resolution, and what a frame's time grows with"));
        visit(field("pathFramesAround", self.pathFramesAround)
                  .range(0, 8)
                  .unit("frames")
                  .doc("paths: a frame's lattice also gathers the paths of this many frames either side of it (fewer "
                       "towards the scene's first or last frame, more on the other side), each traced once and moved to "
                       "the frame's instant by the cloud's velocity: 2n + 1 frames' paths for one frame's time, so less "
                       "noise and less flicker from frame to frame, the light blurred over that time"));
    }
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
inline constexpr EnumName<IntegratorKind> kIntegratorKindNames[] = {{IntegratorKind::Fast, "fast"},
                                                                    {IntegratorKind::Reference, "reference"}};
constexpr const auto& enumNames(IntegratorKind) { return kIntegratorKindNames; }

/// How a ray integrates the medium.
struct IntegratorSettings {
    IntegratorKind kind = IntegratorKind::Fast;
    int maxBounces = 1000; ///< Russian roulette may end a path after three
    double volumeStep = 0.5;
    /// By VolumeRayIntersector, instead of across the cloud's whole box.
    bool skipEmptySpace = true;
    MultipleScatteringSettings multipleScattering;

    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("integrator", self.kind)
                  .doc("fast: ray march with light grids and octaves; reference: an unbiased volumetric path tracer, "
                       "noisy, for many samples per pixel"));
        visit(field("maxBounces", self.maxBounces)
                  .range(1, 1e6)
                  .doc("reference integrator: scattering and reflection events per path (1: single scattering); paths "
                       "also end by Russian roulette"));
        visit(field("volumeStep", self.volumeStep).range(1e-6, 1e9).unit("world units").doc("fast integrator: ray-march step"));
        visit(field("skipEmptySpace", self.skipEmptySpace).doc("march only through OpenVDB nodes holding density"));
        visit(field("multipleScattering", self.multipleScattering)
                  .doc("the fast integrator's light scattered many times: in octaves (Wrenninge, Production Volume "
                       "Rendering, 2017), or traced by the reference's paths once per frame"));
    }
};

struct RenderSettings {
    CameraSettings camera;
    SunSettings sun;
    SkySettings sky;
    ImageSettings image;
    ViewSettings view;
    MediumSettings medium;
    IntegratorSettings integrator;

    /// Checks every part; keys as in a scene file ("camera/fovDegrees",
    /// "render/resolution/0", "render/albedo", ...). Throws OptionError.
    void validate() const;

    /// A content hash of every setting (its declaration's fields): frames
    /// rendered with another are stale.
    uint64_t hash() const;

    /// The settings at frame (fractional, the shutter's instants between
    /// frames): every keyed value there, the camera placed on its path.
    RenderSettings at(double frame) const;

    /// A scene file's keys of how it is seen: camera, sun, sky, and the
    /// "render" object holding the image's, the medium's and the integrator's.
    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("camera", self.camera).doc("a pinhole camera"));
        visit(field("sun", self.sun).doc("the sun, a directional light"));
        visit(field("sky", self.sky).doc("the sky's gradient; it lights surfaces and the cloud"));
        visit(group("render", "the image and how it is shown, the cloud as a medium, and how the light is integrated",
                    [&self](auto& render) {
                        render(inlineFields(self.image));
                        render(inlineFields(self.view));
                        render(inlineFields(self.medium));
                        render(inlineFields(self.integrator));
                    }));
    }
};

} // namespace vfield
