#pragma once
/// @file scene_run.h
/// Scene -> a simulation folder and its images in one run, as `vfield run`
/// makes them: OUT/sim/ (simulation_run.h) and OUT's frames (render_run.h).
/// The renderer follows the simulation on a thread of its own, rendering each
/// frame once the simulation has written it: either stage's parts that run on
/// one thread (a file written, a frame's light prepared) leave the other
/// cores to the other stage instead of idle. The files are the ones a
/// simulation followed by a render writes, byte for byte but for OpenVDB's
/// random file ids, and a rerun resumes both stages as each resumes alone.

#include <vfield/run/render_run.h>
#include <vfield/run/simulation_run.h>

#include <string>

namespace vfield {

struct SceneRunSummary {
    SimulateSummary simulation;
    RenderRunSummary render;
};

/// Simulates the scene into outputDir/sim and renders it into outputDir, the
/// render a frame behind the simulation at least. The options are each
/// stage's own (their frame ranges should agree; render.waitForFrame is
/// set here). An error in either stage stops both, and is the one thrown:
/// the simulation's when the render failed for want of its frames.
SceneRunSummary runScene(const Scene& scene, const std::string& outputDir, SimulateOptions simulate, RenderRunOptions render);

} // namespace vfield
