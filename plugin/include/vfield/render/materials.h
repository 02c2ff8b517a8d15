#pragma once
/// @file materials.h
/// How surfaces are coloured and lit, stated once so that every back-end
/// (vfield's own renderer and the POV-Ray export) shades them alike.

#include <vfield/render/render_settings.h>

namespace vfield {

/// How a surface is coloured.
enum class SurfaceMaterial {
    Terrain, ///< grass, rock and snow by height and slope
    Painted  ///< one base colour
};

/// Diffuse reflectance (linear RGB) of a surface point with unit normal
/// `normal`; terrain colours depend on where the height lies in [low, high],
/// on the slope, and on world-space noise from metres to pixels across.
Vec3d surfaceAlbedo(SurfaceMaterial material, const Vec3d& position, const Vec3d& normal, double low, double high);

/// The normal to shade with: terrain's is tilted by bumps of world-space
/// noise a few units across; painted surfaces keep theirs.
Vec3d shadingNormal(SurfaceMaterial material, const Vec3d& position, const Vec3d& normal);

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

} // namespace vfield
