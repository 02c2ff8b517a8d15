#pragma once
// Scene texts for the simulator tests.

#include <vfield/scene/scene.h>

#include <string>

namespace vfield::test {

/// A single particle (count 1, no objects) under the given fields; it starts
/// at rest within 1e-9 of the origin.
Scene singleParticleScene(const std::string& fieldsJson, int frames, double drag, double fps = 24.0);

/// A showcase scene file with its particle count and frame range reduced and
/// its displaced detail's voxel doubled.
Scene showcaseAtTestResolution(const std::string& name, int particles, int lastFrame);

} // namespace vfield::test
