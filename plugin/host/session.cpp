#include <vfield/host/session.h>

#include <vfield/core/error.h>

namespace vfield {

Session::Session(const std::string& scenePath)
    : mScene(loadScene(scenePath)), mSimulator(std::make_unique<Simulator>(mScene.simulation))
{}

void Session::stepTo(int frame)
{
    if (frame < mSimulator->frame() || frame > mScene.simulation.lastFrame)
        throw ValueError("cannot step from frame " + std::to_string(mSimulator->frame()) + " to frame " + std::to_string(frame) +
                         " (forwards only, up to " + std::to_string(mScene.simulation.lastFrame) + ")");
    while (mSimulator->frame() < frame) mSimulator->advanceFrame();
}

const DensityGrids& Session::volume()
{
    if (mVolumeFrame != frame()) {
        mVolume = splatParticles(mSimulator->particles(), mScene.volume);
        mVolumeFrame = frame();
    }
    return mVolume;
}

} // namespace vfield
