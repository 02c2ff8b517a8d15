#pragma once
// Progress lines on stderr for long commands: "frame 12/120 ... ETA 0:42".
// On a terminal one line is rewritten in place; otherwise plain lines, so logs
// stay readable. Silent with --quiet.

#include <vfield/core/stopwatch.h>
#include <vfield/scene/simulation_run.h>

#include <string>

namespace vfield::cli {

class ProgressLine {
public:
    /// unit names what is counted: "frame 12/120", "case 2/7".
    explicit ProgressLine(bool quiet, std::string unit = "frame");
    ~ProgressLine();
    /// done of total finished after elapsed seconds (done may hold the part
    /// of the next one done, for the ETA); detail is appended.
    void update(double done, int total, double elapsedSeconds, const std::string& detail);
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

} // namespace vfield::cli
