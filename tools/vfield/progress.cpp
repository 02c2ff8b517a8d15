#include "progress.h"

#include <cstdio>
#include <stdexcept>
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

std::string parseFrameRange(const std::string& text, int& first, int& last)
{
    const std::size_t dash = text.find('-', 1);
    try {
        std::size_t used = 0;
        first = std::stoi(text.substr(0, dash), &used);
        if (used != (dash == std::string::npos ? text.size() : dash)) throw std::invalid_argument(text);
        last = first;
        if (dash != std::string::npos) {
            const std::string tail = text.substr(dash + 1);
            last = std::stoi(tail, &used);
            if (used != tail.size()) throw std::invalid_argument(text);
        }
    } catch (const std::exception&) {
        return "expected A-B or A, got '" + text + "'";
    }
    if (last < first) return "the range " + text + " ends before it starts";
    return {};
}

std::function<std::string(const std::string&)> frameRangeValidator()
{
    return [](const std::string& text) {
        int first = 0, last = 0;
        return parseFrameRange(text, first, last);
    };
}

} // namespace vfield::cli
