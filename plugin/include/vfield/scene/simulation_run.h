#pragma once
/// @file simulation_run.h
/// Scene -> a folder of files per frame, what a VFX pipeline reads:
///   field.vdb              the static objects' combined `force` grid, world space
///   density.####.vdb       `density` (FloatGrid) and `vel` (Vec3SGrid), world space
///   particles.####.vdb     `particles` (PointDataGrid: P, v, id, pscale)
///   tracks.json            per frame, each dynamic object's position, orientation, velocity
///   stats.json             per frame, particles alive and removed, substeps, clearances
///   state.bin              the state after the last complete frame, to resume from
/// Every file appears atomically. A run that finds a state of the same scene
/// resumes after its frame, and gives the same result as an uninterrupted run.

#include <vfield/scene/scene.h>
#include <vfield/sim/clearance.h>

#include <functional>
#include <string>
#include <vector>

namespace vfield {

struct FrameProgress {
    int frame = 0;           ///< frame just finished
    int done = 0, total = 0; ///< frames finished in this run, and to finish
    uint64_t alive = 0;
    double elapsedSeconds = 0.0;
};

struct SimulateOptions {
    /// Frames to write, within the scene's range; earlier frames are simulated
    /// but not written. Unset: the scene's whole range.
    std::optional<int> firstFrame, lastFrame;
    /// Called after each frame (from the calling thread).
    std::function<void(const FrameProgress&)> progress;
};

struct FrameRecord {
    int frame = 0;
    uint64_t alive = 0, removed = 0, substeps = 0;
    uint32_t maxSubsteps = 0, dynamicSubsteps = 0;
    ClearanceStats particleClearance, dynamicClearance;
    Vec3d centroid{0.0}; ///< mean particle position, world units
    BBoxd bounds;        ///< box of the particles (empty without particles)
};

struct SimulateSummary {
    std::vector<FrameRecord> frames;             ///< every frame simulated so far, resumed ones included
    int resumedAfterFrame = -1;                  ///< the frame a saved state was resumed after, or -1
    std::vector<std::string> warnings;           ///< e.g. open meshes whose inside is undefined
    ClearanceStats worstParticles, worstDynamic; ///< minima over all frames, penetrations summed
};

SimulateSummary simulateScene(const Scene& scene, const std::string& outputDir, const SimulateOptions& options = {});

/// "density.0007.vdb" style names.
std::string frameFileName(const std::string& stem, int frame, const std::string& extension);

} // namespace vfield
