#include "progress.h"

#include <cstdio>
#include <unistd.h>

namespace vfield::cli {

ProgressLine::ProgressLine(bool quiet) : mQuiet(quiet), mIsTerminal(::isatty(STDERR_FILENO) != 0) {}

ProgressLine::~ProgressLine()
{
    if (mOpenLine) std::fputc('\n', stderr);
}

void ProgressLine::update(int done, int total, double elapsed, const std::string& detail)
{
    if (mQuiet) return;
    const double remaining = done > 0 ? elapsed / done * (total - done) : 0.0;
    const int seconds = int(remaining + 0.5);
    std::fprintf(stderr, "%sframe %d/%d  %s  elapsed %.1fs  ETA %d:%02d%s", mIsTerminal ? "\r\033[K" : "", done, total,
                 detail.c_str(), elapsed, seconds / 60, seconds % 60, mIsTerminal ? "" : "\n");
    std::fflush(stderr);
    mOpenLine = mIsTerminal;
}

} // namespace vfield::cli
