#pragma once
/// @file scattered_light.h
/// The fast integrator's multiply scattered light gathered from the
/// reference's camera paths (MultipleScatteringMethod::Paths).

#include <vfield/render/embree/cloud_volume.h>
#include <vfield/render/embree/renderer.h>

namespace vfield {

/// For the fast integrator (MultipleScatteringMethod::Paths): the light a
/// camera ray scattering in the cloud receives from all but the sun's direct
/// light there (multiply scattered sunlight, the sky, the lit ground), on a
/// lattice over the cloud's box (MultipleScatteringSettings::pathSpacing apart). Up
/// to MultipleScatteringSettings::pathsPerFrame of the reference's camera paths,
/// aimed over the part of the image where the cloud's box is, each carry it
/// back from where they first scatter; each lattice point is their mean,
/// weighted as a trilinear read there weighs them. The march reads the
/// lattice where camera rays scatter, as often as the paths did, so over
/// the image its reads keep the paths' mean at any spacing. Points no path
/// came near take their neighbours' mean. frame.volume must be non-empty.
ScatteredLightGrid traceScatteredLight(const FrameToRender& frame);

} // namespace vfield
