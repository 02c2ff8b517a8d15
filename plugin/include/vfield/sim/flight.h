#pragma once
/// @file flight.h
/// A dynamic object's state, and how it turns: its heading follows its
/// velocity at once, its pitch and (with bank) its roll follow at most at
/// their rates (ObjectSettings). Pushing it is the simulator's (the paper's hit
/// test against every other field, simulator.h).

#include <vfield/core/transform.h>
#include <vfield/sim/scene_setup.h>

namespace vfield {

/// A dynamic object's state at a frame.
struct DynamicState {
    Transform pose;      ///< pivot = the mesh's object-space origin
    Vec3d velocity{0.0}; ///< world units / s
    double roll = 0.0;   ///< radians about the nose; negative: left wing up (banking into a right turn)
    double pitch = 0.0;  ///< radians, nose up
};

/// Turns a dynamic object over a substep of dt (0: at once): heading at once
/// to its velocity (nose +x, up +y), pitch towards the velocity's and, with
/// bank, roll into the turn from the sideways acceleration, each at most at
/// its rate. Roll follows the acceleration, which jumps tenfold at a field's
/// surface leaves: unlimited, it would flip sign within a substep.
void turnToVelocity(DynamicState& state, const Vec3d& acceleration, const ObjectSettings& spec, double dt);

} // namespace vfield
