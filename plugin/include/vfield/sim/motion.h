#pragma once
/// @file motion.h
/// The substep every moving thing of a simulation takes, particles and
/// dynamic objects alike (world units, seconds): how long it may be, and the
/// step itself.

#include <vfield/core/math.h>

namespace vfield {

/// The longest dt for which |v| dt + |a| dt^2 <= reach (the substep's travel bound).
double stepLimit(double speed, double acceleration, double reach);

/// One substep of dv/dt = a - drag v with a held constant: the velocity
/// relaxes exactly towards the terminal velocity a / drag, as exp(-drag dt),
/// so any drag is stable (an explicit step overshoots once drag dt > 1); the
/// position moves with the new velocity (semi-implicit Euler, which reacts to
/// repulsion within the substep). With no drag this is v += a dt, x += v dt.
/// The travel, |v_new| dt, is at most |v| dt + |a| dt^2: what stepLimit bounds.
void integrateWithDrag(Vec3d& x, Vec3d& v, const Vec3d& a, double drag, double dt);

} // namespace vfield
