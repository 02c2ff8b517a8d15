// The flight model: dynamic objects pushed by the paper's hit test of their
// triangle centroids against every other field, turning to face their velocity.

#include <vfield/sim/simulator.h>

#include <vfield/sim/motion.h>

#include <algorithm>
#include <cmath>

namespace vfield {

namespace {

constexpr double kPi = 3.14159265358979323846;

} // namespace

void turnToVelocity(DynamicState& state, const Vec3d& acceleration, const ObjectSettings& spec, double dt)
{
    const Vec3d& velocity = state.velocity;
    const double horizontal = std::hypot(velocity[0], velocity[2]);
    if (velocity.length() < 1e-6) return;
    const double heading = std::atan2(-velocity[2], velocity[0]);
    double targetRoll = 0.0;
    if (spec.bank && horizontal > 1e-6) {
        // Sideways acceleration to the left (up x forward) rolls the left wing
        // down: a negative turn about the nose (+x).
        const Vec3d forward(velocity[0] / horizontal, 0, velocity[2] / horizontal);
        const Vec3d left = Vec3d(0, 1, 0).cross(forward);
        targetRoll = std::clamp(std::atan2(acceleration.dot(left), 9.81), -kPi / 3, kPi / 3);
    }
    const auto approach = [dt](double from, double to, double degreesPerSecond) {
        if (dt <= 0.0) return to;
        const double most = degreesPerSecond * kPi / 180.0 * dt;
        return from + std::clamp(to - from, -most, most);
    };
    state.pitch = approach(state.pitch, std::atan2(velocity[1], horizontal), spec.maxPitchRate);
    state.roll = approach(state.roll, targetRoll, spec.maxRollRate);
    state.pose.rotation =
        (Quatd(Vec3d(0, 1, 0), heading) * Quatd(Vec3d(0, 0, 1), state.pitch) * Quatd(Vec3d(1, 0, 0), -state.roll)).unit();
}

Transform Simulator::poseAt(std::size_t object, double time) const
{
    if (!mObjects[object].spec->isDynamic) return mStates[object].pose;
    const double t0 = mSetup.frameTime(mFrame - 1), t1 = mSetup.frameTime(mFrame);
    const double s = t1 > t0 ? std::clamp((time - t0) / (t1 - t0), 0.0, 1.0) : 1.0;
    return interpolate(mStatesAtFrameStart[object].pose, mStates[object].pose, s);
}

void Simulator::advanceDynamicObjects(double t0, double t1, const std::function<void()>& afterSubstep)
{
    std::vector<std::size_t> dynamic;
    for (std::size_t i = 0; i < mObjects.size(); ++i)
        if (mObjects[i].spec->isDynamic) dynamic.push_back(i);
    if (dynamic.empty()) return;

    const double reach = mSetup.solver.cfl * mFinestCell;
    std::vector<double> rollAtStart;
    for (const std::size_t i : dynamic) rollAtStart.push_back(mStates[i].roll);
    double t = t0;
    uint32_t substeps = 0;
    while (t < t1) {
        // All dynamic objects share a substep, so each sees the others where they are.
        std::vector<Vec3d> acceleration(dynamic.size());
        double dt = t1 - t;
        for (std::size_t d = 0; d < dynamic.size(); ++d) {
            const std::size_t i = dynamic[d];
            const ObjectSettings& spec = *mObjects[i].spec;
            const DynamicState& state = mStates[i];
            Vec3d a = fieldAcceleration(mObjectFields[i], state.pose.translation, t);
            // The paper's hit test: this object's triangle centroids against every other field.
            for (const std::size_t j : mRepulsive) {
                if (j == i) continue;
                const Transform& other = mStates[j].pose;
                std::vector<Vec3d> points;
                points.reserve(mObjects[i].centroids.size());
                for (const Vec3d& c : mObjects[i].centroids)
                    points.push_back(other.objectFromWorld(state.pose.worldFromObject(c)));
                a += other.rotateToWorld(mObjects[j].field->hitTest(points)) / spec.mass;
            }
            acceleration[d] = a;
            // Turning moves the far parts too: roll and pitch at most at their
            // rates, heading as fast as the velocity turns (capped at a radian a frame).
            const double speed = state.velocity.length();
            const double turnRate = (spec.maxRollRate + spec.maxPitchRate) * kPi / 180.0 +
                                    a.length() / std::max(speed, a.length() * (t1 - t0) + 1e-12);
            dt = std::min(dt, stepLimit(speed + turnRate * mObjects[i].radius * state.pose.scale, a.length(), reach));
        }
        dt = std::max(dt, 1e-9 * (t1 - t0)); // progress even if a limit collapses
        for (std::size_t d = 0; d < dynamic.size(); ++d) {
            DynamicState& state = mStates[dynamic[d]];
            const ObjectSettings& spec = *mObjects[dynamic[d]].spec;
            const Vec3d netAcceleration = acceleration[d] - spec.drag * state.velocity;
            integrateWithDrag(state.pose.translation, state.velocity, acceleration[d], spec.drag, dt);
            turnToVelocity(state, netAcceleration, spec, dt);
        }
        t = (t1 - t <= dt) ? t1 : t + dt;
        ++substeps;
        if (afterSubstep) afterSubstep();
    }
    mLastStep.dynamicSubsteps = substeps;
    for (std::size_t d = 0; d < dynamic.size(); ++d)
        mLastStep.maxRollChange =
            std::max(mLastStep.maxRollChange, std::abs(mStates[dynamic[d]].roll - rollAtStart[d]) * 180.0 / kPi);
}

} // namespace vfield
