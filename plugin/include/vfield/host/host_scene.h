#pragma once
/// @file host_scene.h
/// What a host application (Blender, Houdini) needs to rebuild a simulated
/// scene without reading vfield's scene format: SIM/host/host.json and the
/// objects' meshes as OBJ beside it. host.json holds, in vfield's world (y up,
/// right-handed, world units), with paths relative to itself:
///   fps, frames [first, last]   the frames simulated (stats.json)
///   volume     the density sequence's file pattern (#### the frame), its
///              grids (`density`, `vel` in world units per second) and the
///              medium: extinction per unit density, albedo, the two lobes
///   tracks     tracks.json, whose matrices place the dynamic objects
///   objects    name, mesh (OBJ), space ("world": placed; "object": placed by
///              its track), material ("terrain" or "painted" with a colour)
///   camera     vertical field of view, resolution, and a pose per frame
///              when it follows an object (else one)
///   sun, sky   as the scene's render settings state them
/// Written by `vfield simulate` after every run and by `vfield export-scene`.

#include <vfield/scene/scene.h>

#include <string>

namespace vfield {

class SimFolder;

/// The host files' folder of a simulation folder: SIM/host.
std::string hostSceneDir(const SimFolder& simulation);

/// Writes SIM/host/host.json and SIM/host/<object>.obj for the frames the
/// simulation holds (stats.json). Every file is written atomically. Throws
/// FileError when the simulation folder holds no finished frame.
void writeHostScene(const Scene& scene, const SimFolder& simulation);

} // namespace vfield
