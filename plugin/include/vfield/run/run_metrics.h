#pragma once
/// @file run_metrics.h
/// A simulation folder (sim_folder.h) -> what a comparison of repulsion
/// methods reports about it: the guarantees (penetrations, clearances), the
/// quality of the motion (smoothness, stalls) and the cost (the fields' build
/// time and memory, substeps), and whether a cloud stands while its air flows
/// (a cap cloud). Read from the folder's files only: stats.json, tracks.json,
/// the particles.####.vdb of every frame and the density.####.vdb of the
/// second half's.

#include <vfield/folder/sim_folder.h>

#include <cstdint>
#include <string>
#include <vector>

namespace vfield {

/// A dynamic object's path, from its velocity at every frame.
struct ObjectMotion {
    std::string name;
    double cruiseSpeed = 0.0;   ///< median speed over the frames, world units / s
    double meanJerk = 0.0;      ///< mean |d^3 x / dt^3| by finite differences of the frames, world units / s^3
    double peakJerk = 0.0;      ///< largest of those
    double stallSeconds = 0.0;  ///< time spent below 10% of the cruise speed in spells longer than a second
    double minClearance = 0.0;  ///< closest approach to any other object over all substeps, world units
    bool clearanceExact = true; ///< false: minClearance is the level sets' lower bound (farther apart)
};

struct RunMetrics {
    std::string folder;
    std::vector<FieldRecord> fields;
    int frames = 0;
    uint64_t particles = 0;     ///< alive at the first frame
    uint64_t penetrations = 0;  ///< particle samples inside an object, all frames
    double minClearance = 0.0;  ///< particles, over all frames, world units
    double meanClearance = 0.0; ///< particles, over all frames (ClearanceStats::mean)
    double meanCurvature = 0.0; ///< of the particles' paths, radians per world unit (frame to frame)
    /// Particles below 10% of the median speed for over a second, at any time,
    /// counted while the median particle moves at least its diameter a second
    uint64_t trapped = 0;
    double substepsPerParticleFrame = 0.0;
    double simulateSeconds = 0.0; ///< wall clock of all frames (FrameRecord::seconds), field builds excluded
    uint64_t contacts = 0;        ///< particle contacts with dynamic objects (StepStats)
    /// Whether the cloud stands while its air flows through it, over the
    /// frames' second half: the farthest apart its density's centroid stood
    /// at two of them, its length along its particles' mean motion (the span
    /// holding the middle 90% of its density, averaged over the frames), world
    /// units, and its particles' median speed, world units / s. Zero without density.
    double centroidWander = 0.0, cloudLength = 0.0, medianSpeed = 0.0;
    Vec3d meanCentroid{0.0};           ///< where the density's centroid stood, on average over those frames
    std::vector<ObjectMotion> objects; ///< dynamic objects, by name
};

/// Throws FileError for a folder without a simulation or with unreadable files.
RunMetrics measureRun(const std::string& folder);

} // namespace vfield
