#pragma once
/// @file renderer.h
/// Surfaces (Embree) + a cloud volume (OpenVDB) + camera, sun and sky -> a
/// linear RGBA image with depth. Surfaces are shaded by the sun (shadowed by
/// surfaces and by the cloud) and the sky; the cloud is composited between
/// the camera and the first surface, so it sits correctly in front of or behind hills.
///
/// Two integrators (IntegratorKind): the fast one, and a reference path
/// tracer (path_tracer.h) that the fast one is measured against.
///
/// Every sample's random numbers come from a counter-based generator keyed by
/// (the frame's noise stream, pixel, sample), so images are identical for any
/// thread count; the stream is the scene's seed (ImageSettings::noiseStream),
/// the same every frame unless the seed is animated.

#include <vfield/render/camera.h>
#include <vfield/render/cloud_motion.h>
#include <vfield/render/embree/cloud_volume.h>
#include <vfield/render/embree/surfaces.h>
#include <vfield/render/frame_image.h>
#include <vfield/render/materials.h>
#include <vfield/render/screen_motion.h>

#include <map>
#include <vector>

namespace vfield {

struct ScatteredPaths;

struct FrameToRender {
    const RenderSettings* settings = nullptr; ///< image size and samples, sun, sky, medium
    const SurfaceScene* surfaces = nullptr;
    std::map<int, SurfaceMaterial> materials;                            ///< per object; painted grey where missing
    const CloudVolume* volume = nullptr;                                 ///< may be null: surfaces only
    Camera camera{Vec3d(0, 0, 1), Vec3d(0.0), Vec3d(0, 1, 0), 45, 1, 1}; ///< set per frame; at the shutter's open
    std::optional<Camera> closingCamera; ///< at the shutter's close, for a camera that moves over it
    /// The cloud's motion over the shutter (ImageSettings::shutterOpen and
    /// shutterClose); null: the cloud as the frame holds it.
    const CloudMotion* motion = nullptr;
    /// The cloud's velocity (world units a second), for its light gathered
    /// over frames (MultipleScatteringSettings::pathFramesAround); may be null.
    const openvdb::Vec3SGrid* velocity = nullptr;
    /// The paths the fast integrator's lattice gathers (traceScatteredPaths),
    /// the frame's own and those of the frames around it; empty: it traces
    /// the frame's own.
    std::vector<const ScatteredPaths*> scatteredPaths;
    double secondsPerFrame = 1.0 / 24.0;           ///< a frame in seconds, for the cloud's motion
    const ScreenMotion* screenMotion = nullptr;    ///< for the passes' motion vectors; null: none
    int frame = 0;                                 ///< keys the random numbers
    double terrainLow = 0.0, terrainHigh = 1.0;    ///< heights for the terrain's colours
    bool passes = false;                           ///< render RenderImage::passes too
    std::function<void(double fraction)> progress; ///< FrameView::progress
};

/// Renders with the settings' integrator (IntegratorSettings::kind).
RenderImage renderFrame(const FrameToRender& frame);

/// A surface point as every integrator shades it: the normal to shade with
/// and its diffuse albedo, from its object's material and the noise at the
/// point, or the noise given (drawn elsewhere in the pixel: see SurfaceNoise).
struct SurfaceShading {
    Vec3d normal;
    Vec3d albedo;
};
SurfaceMaterial surfaceMaterial(const FrameToRender& frame, int object);
/// The width of a camera pixel's footprint where the ray `dir` from the
/// camera hits, world units: how fine the surface's noise is drawn there.
double pixelFootprint(const FrameToRender& frame, const SurfaceHit& hit, const Vec3d& dir);
SurfaceShading surfaceShading(const FrameToRender& frame, const SurfaceHit& hit);
/// Where rays leaving a surface point start (towards the sun, or bouncing):
/// off the surface, so that they do not find the surface itself.
Vec3d shadowRayOrigin(const SurfaceHit& hit);
SurfaceShading surfaceShading(const FrameToRender& frame, const SurfaceHit& hit, const SurfaceNoise& noise);

} // namespace vfield
