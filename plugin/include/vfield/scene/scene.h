#pragma once
/// @file scene.h
/// A scene file (JSON, "version": 1, documented in scenes/README.md) parsed
/// once into every stage's typed options. Nothing after this sees JSON.

#include <vfield/render/render_settings.h>
#include <vfield/sim/scene_setup.h>
#include <vfield/volume/density_splat.h>

#include <cstdint>
#include <string>

namespace vfield {

struct Scene {
    std::string path;        ///< the scene file
    uint64_t contentHash = 0; ///< hash of the file's bytes: a resumed run must be of the same scene
    SimulationSetup simulation;
    VolumeOptions volume;
    RenderSettings render;

    const ObjectSpec* findObject(const std::string& name) const;
};

/// Reads and checks a scene file. Errors name the file and the JSON path (or
/// line and column for syntax errors); unknown keys are errors; paths inside
/// resolve against the scene file's folder; absurd sizes are refused here.
Scene loadScene(const std::string& path);
/// The same from text (file names the source in messages and anchors paths).
Scene parseScene(const std::string& text, const std::string& file);

} // namespace vfield
