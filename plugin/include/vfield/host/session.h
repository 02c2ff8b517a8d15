#pragma once
/// @file session.h
/// libvfield for host applications: load a scene, step to a frame, read the
/// frame's density grid and particles, all in memory (no files written).

#include <vfield/scene/scene.h>
#include <vfield/sim/simulator.h>
#include <vfield/volume/density_splat.h>

#include <memory>
#include <string>

namespace vfield {

class Session {
public:
    /// Reads the scene and builds its fields. Throws vfield::Error on bad input.
    explicit Session(const std::string& scenePath);

    const Scene& scene() const { return mScene; }
    int frame() const { return mSimulator->frame(); }
    /// Advances to frame (forwards only, within the scene's range).
    void stepTo(int frame);

    const ParticleSet& particles() const { return mSimulator->particles(); }
    /// The current frame's `density` and `vel` grids (splatted on first use).
    const DensityGrids& volume();

private:
    Scene mScene;
    std::unique_ptr<Simulator> mSimulator;
    DensityGrids mVolume;
    int mVolumeFrame = -1;
};

} // namespace vfield
