#pragma once
/// @file motion.h
/// The substep every moving thing of a simulation takes, particles and
/// dynamic objects alike (world units, seconds): how long it may be, and the
/// step itself.

#include <vfield/core/math.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace vfield {

// Inline, all of it: every particle's substep calls it.

/// The longest dt for which |v| dt + |a| dt^2 <= reach (the substep's travel bound).
inline double stepLimit(double speed, double acceleration, double reach)
{
    if (acceleration <= 0.0) return speed > 0.0 ? reach / speed : std::numeric_limits<double>::infinity();
    return 2.0 * reach / (speed + std::sqrt(speed * speed + 4.0 * acceleration * reach));
}

/// integrateWithDrag's two exponentials for one h = drag dt, kept for the
/// next substep with the same h: a particle of a cloud takes, as a rule, one
/// substep a frame, of the same length as its neighbours'.
class DragFactors {
public:
    void update(double drag, double dt)
    {
        const double h = drag * dt;
        if (h == mH) return;
        mH = h;
        // (1 - e^-h) / h, by its series where the closed form loses precision.
        mRelaxed = h < 1e-5 ? 1.0 - h / 2.0 + h * h / 6.0 : -std::expm1(-h) / h;
        mDecay = std::exp(-h);
    }
    /// The substep of integrateWithDrag for the last update's drag and dt.
    void step(Vec3d& x, Vec3d& v, const Vec3d& a, double dt) const
    {
        v = v * mDecay + a * (dt * mRelaxed);
        x += v * dt;
    }

private:
    double mH = -1.0, mDecay = 1.0, mRelaxed = 1.0;
};

/// One substep of dv/dt = a - drag v with a held constant: the velocity
/// relaxes exactly towards the terminal velocity a / drag, as exp(-drag dt),
/// so any drag is stable (an explicit step overshoots once drag dt > 1); the
/// position moves with the new velocity (semi-implicit Euler, which reacts to
/// repulsion within the substep). With no drag this is v += a dt, x += v dt.
/// The travel, |v_new| dt, is at most |v| dt + |a| dt^2: what stepLimit bounds.
inline void integrateWithDrag(Vec3d& x, Vec3d& v, const Vec3d& a, double drag, double dt)
{
    DragFactors factors;
    factors.update(drag, dt);
    factors.step(x, v, a, dt);
}

/// min(remaining, stepLimit(|velocity| + extraSpeed, |acceleration|, reach)),
/// without the square roots and the division when the whole remaining time
/// is plainly within reach (|v| T and |a| T^2 each at most half of it), as
/// for most particles' one substep a frame.
inline double stepWithin(double remaining, const Vec3d& velocity, double extraSpeed, const Vec3d& acceleration, double reach)
{
    const double halfSqr = 0.25 * reach * reach, remainingSqr = remaining * remaining;
    if (extraSpeed == 0.0 && velocity.lengthSqr() * remainingSqr <= halfSqr &&
        acceleration.lengthSqr() * remainingSqr * remainingSqr <= halfSqr)
        return remaining;
    return std::min(remaining, stepLimit(velocity.length() + extraSpeed, acceleration.length(), reach));
}

} // namespace vfield
