#pragma once
/// @file scene.h
/// A scene file (JSON, "version": 1, documented in docs/scenes.md) parsed
/// once into every stage's typed options. Nothing after this sees JSON.

#include <vfield/render/povray/povray_settings.h>
#include <vfield/render/render_settings.h>
#include <vfield/sim/scene_setup.h>
#include <vfield/volume/density_splat.h>

#include <cstdint>
#include <string>
#include <vector>

namespace vfield {

struct Scene {
    static constexpr double kMaxDensityVoxels = 2e9; ///< a cloud's initial box, in density voxels

    std::string path; ///< the scene file
    int version = 1;
    SimulationSettings simulation;
    VolumeSettings volume; ///< resolved: defaults filled in from the clouds' particle radii
    RenderSettings render;
    PovraySettings povray;

    const ObjectSettings* findObject(const std::string& name) const;
    /// Checks every part (keys as in the file: "clouds/0/count",
    /// "render/resolution/0", ...), that a followed object is a dynamic object
    /// of the scene, and that each cloud's density grid fits. Throws OptionError.
    void validate() const;

    /// Every key of a scene file (docs/scenes.md's tables are generated from it).
    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("version", self.version).required().doc("the scene format's version: must be 1"));
        visit(inlineFields(self.simulation));
        visit(field("volume", self.volume).doc("the density grids"));
        visit(inlineFields(self.render));
        visit(field("povray", self.povray).doc("the POV-Ray back-end's own settings"));
    }
};

/// One change to a scene file's JSON before it is read, as Houdini's and
/// Blender's command lines allow: the value (JSON text) at a JSON pointer,
/// e.g. {"/clouds/0/count", "5000"} or {"/render/resolution", "[320, 180]"}.
/// A "*" in the pointer stands for every element of an array
/// ("/objects/*/repulsion/method"): below it, an element whose path passes a
/// false (an object without a field) is left alone, and true counts as {}.
struct SceneOverride {
    std::string pointer;
    std::string value;
};

/// Reads and checks a scene file. Errors name the file and the JSON path (or
/// line and column for syntax errors); unknown keys are errors; paths inside
/// resolve against the scene file's folder; absurd sizes are refused here.
Scene loadScene(const std::string& path, const std::vector<SceneOverride>& overrides = {});
/// The same from text (file names the source in messages and anchors paths).
Scene parseScene(const std::string& text, const std::string& file);

} // namespace vfield
