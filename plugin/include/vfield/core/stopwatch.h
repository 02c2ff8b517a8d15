#pragma once
/// @file stopwatch.h
/// Wall-clock seconds since a point, for the timings a run reports and for
/// progress told at most once a period.

#include <chrono>

namespace vfield {

class Stopwatch {
public:
    /// Seconds since construction or the last restart.
    double seconds() const { return std::chrono::duration<double>(Clock::now() - mStart).count(); }
    /// Seconds since construction or the last restart, and starts again.
    double lap()
    {
        const Clock::time_point now = Clock::now();
        const double elapsed = std::chrono::duration<double>(now - mStart).count();
        mStart = now;
        return elapsed;
    }

    /// Whether at least period seconds have passed since construction or the
    /// last restart, and if so starts again: a long job asked often (an
    /// iteration, a tile) tells its progress only when this says so.
    bool lapAfter(double period)
    {
        const Clock::time_point now = Clock::now();
        if (std::chrono::duration<double>(now - mStart).count() < period) return false;
        mStart = now;
        return true;
    }

private:
    using Clock = std::chrono::steady_clock;
    Clock::time_point mStart = Clock::now();
};

} // namespace vfield
