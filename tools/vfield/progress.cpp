#include "progress.h"

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

void ProgressLine::update(double done, int total, double elapsed, const std::string& detail)
{
    if (mQuiet) return;
    // Nothing done yet: no rate to tell the rest by.
    char eta[32] = "ETA -:--";
    if (done > 0) {
        const int seconds = int(elapsed / done * (total - done) + 0.5);
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

} // namespace vfield::cli
