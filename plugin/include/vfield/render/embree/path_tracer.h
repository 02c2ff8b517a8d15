#pragma once
/// @file path_tracer.h
/// The reference integrator (IntegratorKind::Reference): an unbiased
/// volumetric path tracer over the same scene as the fast one: Embree's
/// surfaces with the same materials, the cloud's OpenVDB density (read
/// trilinearly, sigma_t = extinction x density), the same sun, sky and haze.
///
/// - Free paths through the cloud by delta tracking, cell by cell of a grid
///   of majorants (the largest extinction a read can give in each cell, as
///   pbrt-v4's), empty cells skipped; transmittance towards the sun by ratio
///   tracking under the same bounds (with Russian roulette once it is small).
/// - At a collision the path scatters with probability albedo (its weight
///   scaled by it), in a direction drawn from the two-lobe phase function.
/// - Surfaces are Lambertian; directions drawn by the cosine.
/// - The sun, a delta light, is sampled at every vertex (next-event
///   estimation); the sky dome is found by paths that escape.
/// - Paths end after IntegratorSettings::maxBounces events, or by Russian
///   roulette on their weight after three.
/// Converges to the scene's light as samples grow: noisy, slow, and what the
/// fast integrator's approximations are measured against.

#include <vfield/render/embree/renderer.h>

namespace vfield {

RenderImage renderReference(const FrameToRender& frame);

} // namespace vfield
