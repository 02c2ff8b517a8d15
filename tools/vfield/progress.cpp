#include "progress.h"

#include <algorithm>
#include <cstdio>
#include <unistd.h>
#include <utility>

namespace vfield::cli {

ProgressLine::ProgressLine(bool quiet, std::string unit)
    : mQuiet(quiet), mIsTerminal(::isatty(STDERR_FILENO) != 0), mUnit(std::move(unit))
{}

ProgressLine::~ProgressLine()
{
    if (mOpenLine) std::fputc('\n', stderr);
}

void ProgressLine::update(double done, int total, double elapsed, const std::string& detail, std::optional<double> fractionDone)
{
    if (mQuiet) return;
    const double fraction = fractionDone.value_or(total > 0 ? done / total : 0.0);
    // Nothing done yet: no rate to tell the rest by.
    char eta[32] = "ETA -:--";
    if (fraction > 0) {
        const int seconds = int(elapsed / fraction * (1.0 - fraction) + 0.5);
        std::snprintf(eta, sizeof eta, "ETA %d:%02d", seconds / 60, seconds % 60);
    }
    std::fprintf(stderr, "%s%s %d/%d  %s  elapsed %.1fs  %s%s", mIsTerminal ? "\r\033[K" : "", mUnit.c_str(), int(done), total,
                 detail.c_str(), elapsed, eta, mIsTerminal ? "" : "\n");
    std::fflush(stderr);
    mOpenLine = mIsTerminal;
}

void ProgressLine::step(const std::string& what)
{
    if (mQuiet) return;
    std::fprintf(stderr, "%s%s  elapsed %.1fs%s", mIsTerminal ? "\r\033[K" : "", what.c_str(), mSinceStart.seconds(),
                 mIsTerminal ? "" : "\n");
    std::fflush(stderr);
    mOpenLine = mIsTerminal;
}

void showSimulationProgress(SimulateOptions& options, ProgressLine& progress, const std::string& frameWord)
{
    options.preparing = [&progress](const std::string& step) { progress.step("preparing: " + step); };
    options.progress = [&progress, frameWord](const FrameProgress& p) {
        progress.update(p.done, p.total, p.elapsedSeconds,
                        "(" + frameWord + " " + std::to_string(p.frame) + ", " + std::to_string(p.alive) + " particles)");
    };
}

std::string renderingFrame(int frame, double fraction)
{
    return "rendering frame " + std::to_string(frame) + ": " + std::to_string(int(100.0 * fraction)) + "%";
}

RunProgress::RunProgress(bool quiet, int frames) : mLine(quiet), mFrames(std::max(frames, 1)) {}

void RunProgress::attach(SimulateOptions& simulate, RenderRunOptions& render)
{
    simulate.preparing = [this](const std::string& step) {
        const std::lock_guard<std::mutex> lock(mMutex);
        mLine.step("preparing: " + step);
    };
    simulate.progress = [this](const FrameProgress& p) {
        const std::lock_guard<std::mutex> lock(mMutex);
        mSimulatedShare = p.total > 0 ? double(p.done) / p.total : 1.0;
        mSimulating = "frame " + std::to_string(p.frame) + ", " + std::to_string(p.alive) + " particles";
        show();
    };
    simulate.finished = [this](int lastFrame) {
        const std::lock_guard<std::mutex> lock(mMutex);
        mSimulatedShare = 1.0;
        mSimulating = "through frame " + std::to_string(lastFrame);
        show();
    };
    render.progress = [this](int frame, int done, int, double) {
        const std::lock_guard<std::mutex> lock(mMutex);
        if (!mSinceRenderStarted) mSinceRenderStarted.emplace();
        mRendered = done;
        mRenderedShare = double(done) / mFrames;
        mRendering = "rendered frame " + std::to_string(frame);
        show();
    };
    render.frameProgress = [this](int frame, int done, int, double fraction) {
        const std::lock_guard<std::mutex> lock(mMutex);
        if (!mSinceRenderStarted) mSinceRenderStarted.emplace();
        mRendered = done;
        mRenderedShare = (done + fraction) / mFrames;
        mRendering = renderingFrame(frame, fraction);
        show();
    };
}

void RunProgress::show()
{
    if (!mSinceFirstFrame) mSinceFirstFrame.emplace();
    const double elapsed = mSinceFirstFrame->seconds();
    // Seconds left for a stage that took `seconds` for `share` of its work; unknown before any.
    const auto left = [](double seconds, double share) -> std::optional<double> {
        if (share <= 0.0) return std::nullopt;
        return seconds / share * (1.0 - share);
    };
    const std::optional<double> simulation = left(elapsed, mSimulatedShare);
    const std::optional<double> render =
        mSinceRenderStarted ? left(mSinceRenderStarted->seconds(), mRenderedShare) : std::nullopt;
    double fraction = 0.0; // of the run done, as the line's ETA reads it; 0: no pace known yet
    // A simulation found complete tells nothing of the render's pace.
    if (render || (simulation && mSimulatedShare < 1.0)) {
        const double remaining = std::max(simulation.value_or(0.0), render.value_or(0.0));
        fraction = elapsed + remaining > 0.0 ? elapsed / (elapsed + remaining) : 1.0;
    }
    mLine.update(mRendered, mFrames, elapsed, "(simulated: " + mSimulating + "; " + mRendering + ")", fraction);
}

} // namespace vfield::cli
