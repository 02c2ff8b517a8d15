#pragma once
// The showcases the benchmarks share: the cloud showcase at frame 100 (the
// cloud over the valley, near the terrain: its surfaces, density and camera)
// and the main job at frame 120 (its simulator there, at any particle count).

#include "showcase_samples.h"

#include <vfield/render/embree/renderer.h>
#include <vfield/scene/scene.h>
#include <vfield/sim/simulator.h>

#include <benchmark/benchmark.h>

#include <cstdint>
#include <memory>
#include <string>

namespace vfield::bench {

/// The showcase's surfaces and its frame-100 density (50,000 particles).
struct ShowcaseFrame {
    Scene scene;
    SurfaceScene surfaces;
    TriangleMesh terrain; ///< world space
    openvdb::FloatGrid::Ptr density;

    ShowcaseFrame();
    /// The scene's render settings at another image size and sample count.
    RenderSettings settings(int width, int height, int spp) const;
    /// The frame to render with settings (which must outlive it).
    FrameToRender frame(const RenderSettings& settings, const CloudVolume* volume);
    /// The sun's occlusion by the terrain, for the cloud's lighting.
    CloudLighting::Occlusion sunBlocked() const;
};

/// Built once.
ShowcaseFrame& showcase();

/// The main job (scenes/cloud_bank.json) at frame 120, its bank on the
/// ridge, with `particles` particles (each as dense as the scene's cloud's
/// mass shared among them); simulated once per count. The terrain's
/// surfaces are built once and shared.
struct MainJobFrame {
    Scene scene;
    std::unique_ptr<Simulator> simulator;
    std::string state;                      ///< the simulator's state at frame 120, to reset to
    const SurfaceScene* surfaces = nullptr; ///< the terrain, world space
    /// The scene's render settings at another image size and sample count.
    RenderSettings settings(int width, int height, int spp) const;
    /// The frame to render with settings (which must outlive it).
    FrameToRender frame(const RenderSettings& settings, const CloudVolume* volume) const;
};
MainJobFrame& mainJobAtFrame120(int64_t particles);
/// The particle counts of the main job's scaling rows, 125,000 doubled to 1,000,000.
void mainJobCounts(benchmark::internal::Benchmark* benchmark);

} // namespace vfield::bench
