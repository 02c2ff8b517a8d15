#pragma once
/// @file emission.h
/// CloudSettings (world space) -> the particles a simulation starts with: each
/// cloud's shape filled uniformly, cut into lumps by billow noise, from its
/// own random stream (its seed mixed with the scene's), so the same scene
/// gives the same particles on every machine.

#include <vfield/sim/particles.h>
#include <vfield/sim/scene_setup.h>

namespace vfield {

/// Every cloud's particles, in cloud order, ids from 0; rest positions where
/// they are emitted.
ParticleSet emitClouds(const SimulationSettings& setup);

} // namespace vfield
