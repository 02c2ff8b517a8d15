#pragma once
/// @file frame_volume.h
/// A frame's volume stage, between the simulator and the simulation folder:
/// ParticleSet -> the frame's density file (splatParticles at the scene's
/// volume settings) and its particle file (makeParticleGrid), both stamped
/// with the simulation's inputs hash and the frame.

#include <vfield/folder/sim_folder.h>
#include <vfield/sim/particles.h>
#include <vfield/volume/density_splat.h>

#include <cstdint>

namespace vfield {

/// Splats the particles into the frame's density file while their particle
/// grid is built and written beside it: OpenVDB writes a file on one thread,
/// so the two overlap. Returns the files' fingerprints; adds to stages the
/// splat's and the detail's seconds, and the rest of the stage's as the
/// writing's.
FrameFiles writeFrameVolume(const SimFolder& folder, int frame, const ParticleSet& particles, const VolumeSettings& volume,
                            uint64_t inputsHash, StageSeconds& stages);

} // namespace vfield
