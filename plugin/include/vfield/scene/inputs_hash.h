#pragma once
/// @file inputs_hash.h
/// A hash of everything a simulation's result depends on: every declared
/// field of the simulation setup and the volume options (core/fields.h), and
/// the bytes of every mesh file and elevation image they name. Editing any
/// of them changes it; camera, sun, sky and render settings do not enter it.

#include <vfield/sim/scene_setup.h>
#include <vfield/volume/density_splat.h>

#include <cstdint>

namespace vfield {

/// Throws FileError for an unreadable mesh file.
uint64_t simulationInputsHash(const SimulationSettings& setup, const VolumeSettings& volume);

} // namespace vfield
