#pragma once
/// @file materials.h
/// How surfaces are coloured and lit, stated once so that every back-end
/// (vfield's own renderer and the POV-Ray export) shades them alike.

#include <vfield/render/render_settings.h>
#include <vfield/sim/scene_setup.h>

#include <limits>

namespace vfield {

/// How a surface is coloured.
struct SurfaceMaterial {
    enum class Kind {
        Terrain, ///< grass, rock and snow by height and slope
        Painted  ///< one base colour
    };
    Kind kind = Kind::Painted;
    Vec3d paint{0.62, 0.62, 0.66}; ///< a painted surface's diffuse reflectance, linear RGB (0..1)

    static SurfaceMaterial terrain() { return {Kind::Terrain, Vec3d(0.0)}; }
    static SurfaceMaterial painted(const Vec3d& colour) { return {Kind::Painted, colour}; }
};

/// The world-space noise a surface's shading draws at a point (none for
/// painted surfaces). Apart from the shading so that a renderer can draw it
/// once per pixel and surface, as a texture is filtered. Its features down to
/// 0.75 units are always drawn; finer octaves (`detail`, and bumps within the
/// gradient) only where a pixel is small enough to hold them, as a mipmap
/// would: a rock wall next to the camera shows grain, distant slopes do not
/// shimmer.
struct SurfaceNoise {
    Vec3d bumpGradient{0.0};                     ///< of the bump noise, per world unit
    double broad = 0.0, fine = 0.0, stone = 0.0; ///< colour noise at three scales, about [-1, 1]
    double detail = 0.0;                         ///< colour noise finer than `fine`, about [-1, 1]; 0 where pixels are coarse
};
/// pixelFootprint: the width of the pixel's footprint at the point, world
/// units; octaves with a period under twice it are left out (infinity: none
/// finer than 0.75 units).
SurfaceNoise surfaceNoise(const SurfaceMaterial& material, const Vec3d& position,
                          double pixelFootprint = std::numeric_limits<double>::infinity());

/// Diffuse reflectance (linear RGB) of a surface point with unit normal
/// `normal`; terrain colours depend on where the height lies in [low, high],
/// on the slope, and on the noise at the point.
Vec3d surfaceAlbedo(const SurfaceMaterial& material, const Vec3d& position, const Vec3d& normal, double low, double high,
                    const SurfaceNoise& noise);

/// The normal to shade with: terrain's is tilted by the bumps of its noise, a
/// few units across; painted surfaces keep theirs.
Vec3d shadingNormal(const SurfaceMaterial& material, const Vec3d& normal, const SurfaceNoise& noise);

/// The sky dome's radiance in a unit direction: a gradient from horizon to
/// zenith over the lower half of the sky, haze below the horizon. What lights
/// a scene from the sky; the sun is a light of its own.
Vec3d skyDomeRadiance(const SkySettings& sky, const Vec3d& dir);

/// The sky as a camera sees it: the dome and the sun's glow around its disc.
Vec3d skyRadiance(const RenderSettings& settings, const Vec3d& dir);

/// The light a cloud receives from all around, as an isotropic radiance: the
/// mean of the sky dome over the upper hemisphere and of what lies below
/// (the ground's radiance, or the dome's horizon where there is no ground).
Vec3d cloudAmbientRadiance(const SkySettings& sky, const Vec3d& below);

/// Aerial perspective: what lies at distance d keeps e^(-d / hazeDistance) of
/// its light, the rest is the horizon's haze. Something that covers only part
/// of the view (a cloud of transmittance T: coverage 1 - T) adds only that part
/// of the haze before it: the rest is in the hazed light behind it.
Vec3d throughHaze(const SkySettings& sky, const Vec3d& radiance, double distance, double coverage = 1.0);

/// Light the sky gives a surface with unit normal `normal` (linear RGB
/// irradiance over pi): the zenith's colour facing up, half the horizon's sideways.
Vec3d skyLightOnSurface(const SkySettings& sky, const Vec3d& normal);

/// How a scene object's surface is coloured: terrain and heightmap meshes as
/// terrain, everything else painted in the object's colour.
SurfaceMaterial surfaceMaterialOf(const ObjectSettings& object);

} // namespace vfield
