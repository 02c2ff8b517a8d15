#pragma once
// Progress lines on stderr for long commands: "frame 12/120 ... ETA 0:42".
// On a terminal one line is rewritten in place; otherwise plain lines, so logs
// stay readable. Silent with --quiet.

#include <string>

namespace vfield::cli {

class ProgressLine {
public:
    explicit ProgressLine(bool quiet);
    ~ProgressLine();
    /// done of total finished after elapsed seconds; detail is appended.
    void update(int done, int total, double elapsedSeconds, const std::string& detail);

private:
    bool mQuiet, mIsTerminal;
    bool mOpenLine = false;
};

} // namespace vfield::cli
