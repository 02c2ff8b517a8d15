#include <vfield/run/scene_run.h>

#include <condition_variable>
#include <exception>
#include <limits>
#include <mutex>
#include <thread>

namespace vfield {

namespace {

/// Thrown from the simulation's progress to stop it once the render failed,
/// and from the render's wait to stop it once the simulation failed.
struct OtherStageFailed {};

} // namespace

SceneRunSummary runScene(const Scene& scene, const std::string& outputDir, SimulateOptions simulate, RenderRunOptions render)
{
    const std::string simulationDir = outputDir + "/sim";
    std::mutex mutex;
    std::condition_variable changed;
    // Frames up to this one are in the folder: every frame the simulation
    // reports is written, and one resumed or checked again reports from the
    // first frame it writes afresh, those before it being complete.
    int simulatedThrough = std::numeric_limits<int>::min();
    bool simulationEnded = false, renderFailed = false;

    const auto reportSimulated = simulate.progress;
    simulate.progress = [&](const FrameProgress& progress) {
        {
            const std::lock_guard<std::mutex> lock(mutex);
            if (renderFailed) throw OtherStageFailed{};
            simulatedThrough = progress.frame;
        }
        changed.notify_all();
        if (reportSimulated) reportSimulated(progress);
    };
    std::exception_ptr simulationError;
    render.waitForFrame = [&](int frame) {
        std::unique_lock<std::mutex> lock(mutex);
        changed.wait(lock, [&] { return simulationEnded || simulatedThrough >= frame; });
        if (simulationError) throw OtherStageFailed{};
    };

    SceneRunSummary summary;
    std::thread simulation([&] {
        std::exception_ptr error;
        try {
            summary.simulation = simulateScene(scene, simulationDir, simulate);
        } catch (const OtherStageFailed&) {
            // stopped for the render's error, thrown below
        } catch (...) {
            error = std::current_exception();
        }
        {
            const std::lock_guard<std::mutex> lock(mutex);
            simulationError = error;
            simulationEnded = true;
        }
        changed.notify_all();
    });
    std::exception_ptr renderError;
    try {
        summary.render = renderScene(scene, simulationDir, outputDir, render);
    } catch (const OtherStageFailed&) {
        // stopped for the simulation's error, thrown below
    } catch (...) {
        renderError = std::current_exception();
        const std::lock_guard<std::mutex> lock(mutex);
        renderFailed = true;
    }
    simulation.join();
    if (simulationError) std::rethrow_exception(simulationError);
    if (renderError) std::rethrow_exception(renderError);
    return summary;
}

} // namespace vfield
