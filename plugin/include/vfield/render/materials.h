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
/// `normal`; terrain colours depend on where the height lies in [low, high].
Vec3d surfaceAlbedo(SurfaceMaterial material, const Vec3d& position, const Vec3d& normal, double low, double high);

/// The sky's radiance in a unit direction: a gradient from horizon to zenith
/// over the lower half of the sky, haze below the horizon, and the sun's glow.
Vec3d skyRadiance(const RenderSettings& settings, const Vec3d& dir);

/// Light the sky gives a surface with unit normal `normal` (linear RGB
/// irradiance over pi): the zenith's colour facing up, half the horizon's sideways.
Vec3d skyLightOnSurface(const SkySettings& sky, const Vec3d& normal);

} // namespace vfield
