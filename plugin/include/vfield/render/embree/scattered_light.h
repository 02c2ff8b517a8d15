#pragma once
/// @file scattered_light.h
/// The fast integrator's multiply scattered light gathered from the
/// reference's camera paths (MultipleScatteringMethod::Paths).

#include <vfield/render/embree/cloud_volume.h>
#include <vfield/render/embree/renderer.h>

#include <vector>

namespace vfield {

/// The paths one frame traces: where each first scattered in the cloud, how
/// fast the cloud moves there, and the light it carried back from its later
/// vertices (multiply scattered sunlight, the sky, the lit ground).
struct ScatteredPaths {
    struct Path {
        Vec3d position, velocity, light;
    };
    int frame = 0;
    std::vector<Path> paths;
};

/// For the fast integrator (MultipleScatteringMethod::Paths): up to
/// MultipleScatteringSettings::pathsPerFrame of the reference's camera paths,
/// aimed over the part of the image where the cloud's box is, each followed
/// from where it first scatters. frame.volume must be non-empty;
/// frame.velocity, when set, gives each path's velocity (0 otherwise).
ScatteredPaths traceScatteredPaths(const FrameToRender& frame);

/// The light a camera ray scattering in the cloud receives from all but the
/// sun's direct light there, on a lattice over the frame's cloud box
/// (MultipleScatteringSettings::pathSpacing apart), from the paths of the
/// frames given (the frame's own among them), each moved to the frame's
/// instant by its velocity. Each lattice point is their mean, weighted as a
/// trilinear read there weighs them. The march reads the lattice where camera
/// rays scatter, as often as the paths did, so over the image its reads keep
/// the paths' mean at any spacing. Points no path came near take their
/// neighbours' mean. Summed frame by frame in the order given, each frame's
/// paths in their order: the same lattice for any thread count.
ScatteredLightGrid gatherScatteredLight(const FrameToRender& frame, const std::vector<const ScatteredPaths*>& traced);

} // namespace vfield
