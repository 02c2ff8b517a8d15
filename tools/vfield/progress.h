#pragma once
// Progress lines on stderr for long commands: "frame 12/120 ... ETA 0:42".
// On a terminal one line is rewritten in place; otherwise plain lines, so logs
// stay readable. Silent with --quiet.

#include <vfield/core/stopwatch.h>
#include <vfield/run/render_run.h>
#include <vfield/run/simulation_run.h>

#include <mutex>
#include <optional>
#include <string>

namespace vfield::cli {

class ProgressLine {
public:
    /// unit names what is counted: "frame 12/120", "case 2/7".
    explicit ProgressLine(bool quiet, std::string unit = "frame");
    ~ProgressLine();
    /// done of total finished after elapsed seconds (done may hold the part
    /// of the next one done, for the ETA); detail is appended. The ETA comes
    /// from the fraction of the work done: done / total unless given (two
    /// stages running together, `vfield run`).
    void update(double done, int total, double elapsedSeconds, const std::string& detail,
                std::optional<double> fractionDone = std::nullopt);
    /// A step before the counting starts ("terrain: octree field ..."), with
    /// the seconds since this line was made.
    void step(const std::string& what);

private:
    bool mQuiet, mIsTerminal;
    std::string mUnit;
    Stopwatch mSinceStart;
    bool mOpenLine = false;
};

/// Shows a simulation's preparing steps, then its frames ("(frame 12, 250000
/// particles)"; frameWord: "frame", or "simulated frame" where images follow).
void showSimulationProgress(SimulateOptions& options, ProgressLine& progress, const std::string& frameWord);

/// "rendering frame 12: 40%".
std::string renderingFrame(int frame, double fraction);

/// One line for a simulation and the render following it (`vfield run`,
/// scene_run.h), told from both stages' threads: the frames rendered, what
/// each stage is at, and the ETA: the later of the two stages' ends, each at
/// its own pace (the simulation's from its first frame, the render's from
/// its first report). Averaging the two shares would tell a run whose
/// simulation has finished that little is left while most of its frames are
/// still to render.
class RunProgress {
public:
    /// frames: how many the render is to finish.
    RunProgress(bool quiet, int frames);
    /// Sets both options' progress callbacks to this line; it must outlive the run.
    void attach(SimulateOptions& simulate, RenderRunOptions& render);

private:
    void show(); // with mMutex held

    std::mutex mMutex;
    ProgressLine mLine;
    int mFrames, mRendered = 0;
    double mSimulatedShare = 0.0, mRenderedShare = 0.0;
    std::string mSimulating = "preparing", mRendering = "waiting";
    std::optional<Stopwatch> mSinceFirstFrame, mSinceRenderStarted;
};

} // namespace vfield::cli
