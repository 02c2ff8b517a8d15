// The particle integrator: each particle's own substeps through the sum of
// the fields, bounded by the cells around it, with contact against dynamic
// objects' closed meshes.

#include <vfield/sim/simulator.h>

#include <vfield/sim/motion.h>

#include <openvdb/tools/Interpolation.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

namespace vfield {

namespace {

/// Frames between spatial sorts of the particles: a sort costs about one
/// frame's advection, and in a few frames particles drift too little to spoil
/// the order for the density splat, whose speed depends on it (10x).
constexpr int kSortInterval = 8;

/// Unrotated objects (terrain, as a rule) skip the rotations, which would change nothing.
bool isRotated(const Transform& pose)
{
    const Quatd& q = pose.rotation;
    return !(q.w() == 1.0 && q.x() == 0.0 && q.y() == 0.0 && q.z() == 0.0);
}

Vec3d objectPoint(const Transform& pose, const Vec3d& world)
{
    return isRotated(pose) ? pose.objectFromWorld(world) : (world - pose.translation) / pose.scale;
}

/// The most a trilinear read of a distance grid changes between two points
/// `move` apart: |move_x| + |move_y| + |move_z|, since each axis's slope is
/// a blend of neighbouring voxels' differences, at most one voxel a voxel for
/// a distance. Never above sqrt(3) |move| (equal along a diagonal, sqrt(3)
/// times less along an axis), and without a square root: the test every
/// substep of every particle makes.
double readChangeBound(const Vec3d& move) { return std::abs(move.x()) + std::abs(move.y()) + std::abs(move.z()); }

} // namespace

Vec3d Simulator::fieldAcceleration(const AccelerationFields& fields, const Vec3d& p, double t) const
{
    Vec3d a = fields.leadingSum;
    for (const std::size_t f : fields.rest) a += mSetup.fields[f].accelerationAt(p, mSetup.frameAt(t));
    for (const std::size_t f : fields.turbulence) a += mTurbulence[f].acceleration(p, t);
    return a;
}

Simulator::FieldsAt Simulator::fieldsAt(const Vec3d& p, double time, double mass, RepulsionField::Accessor* accessors,
                                        bool withForces) const
{
    FieldsAt at;
    Vec3d force(0.0), flow(0.0);
    bool inAnyField = false;
    double cell = std::numeric_limits<double>::infinity();
    // Narrowed by each field below; the whole world where none is.
    Vec3d sameMin(-std::numeric_limits<double>::max()), sameMax(std::numeric_limits<double>::max());
    bool sameBoundKnown = withForces;
    for (std::size_t k = 0; k < mRepulsive.size(); ++k) {
        const std::size_t i = mRepulsive[k];
        const SimObject& object = mObjects[i];
        const RepulsionField& field = *object.field;
        Transform moving;
        const Transform& pose = object.spec->isDynamic ? (moving = poseAt(i, time)) : mStates[i].pose;
        const bool inWorld = mWorldIsObject[i];
        const Vec3d local = inWorld ? p : objectPoint(pose, p);
        // Near a field that moves or turns, its cells are not followed: a read decides.
        if (object.spec->isDynamic || (!inWorld && isRotated(pose))) sameBoundKnown = false;
        // A moving field reaches whatever its root sweeps over during the frame.
        const double sweep = k < mFieldSpeed.size() && mFieldSpeed[k] > 0.0 ? mFieldSpeed[k] * mFieldFrameTime / pose.scale : 0.0;
        if (sweep > 0.0) {
            BBoxd reach = field.bounds();
            reach.expand(sweep);
            if (!reach.isInside(local)) continue;
        }
        int level = field.depth(); // beyond the root but within its sweep: as fine as it gets
        if (field.bounds().isInside(local)) {
            // The leaf's level from the voxel holding p: finest-leaf voxels never straddle a leaf.
            if (withForces) {
                const RepulsionField::Sample sample = field.sample(accessors[k], local);
                (field.isFlow() ? flow : force) += !inWorld && isRotated(pose) ? pose.rotateToWorld(sample.force) : sample.force;
                if (field.isFlow() && sample.level > 0) at.inFlow = true;
                level = sample.level;
                if (sameBoundKnown) {
                    const BBoxd& cellBox = field.levelCell(accessors[k], sample);
                    const Vec3d lo = inWorld ? cellBox.min() : pose.worldFromObject(cellBox.min());
                    const Vec3d hi = inWorld ? cellBox.max() : pose.worldFromObject(cellBox.max());
                    sameMin = openvdb::math::maxComponent(sameMin, lo);
                    sameMax = openvdb::math::minComponent(sameMax, hi);
                }
            } else {
                level = field.levelAt(accessors[k], local);
            }
            level = std::max(level, 1);
        } else if (sweep == 0.0) {
            sameBoundKnown = false; // p may step into the field
            continue;
        }
        inAnyField = true;
        cell = std::min(cell, field.cellSize(level) * pose.scale);
        if (k < mFieldSpeed.size()) at.bound.fieldSpeed = std::max(at.bound.fieldSpeed, mFieldSpeed[k]);
    }
    if (inAnyField) at.bound.cell = cell;
    if (sameBoundKnown) at.sameBound = BBoxd(sameMin, sameMax);
    at.acceleration = force / mass + flow;
    return at;
}

void Simulator::measureFieldSpeeds(double t0, double t1)
{
    mFieldFrameTime = t1 - t0;
    mFieldSpeed.assign(mRepulsive.size(), 0.0);
    if (!(t1 > t0)) return;
    for (std::size_t k = 0; k < mRepulsive.size(); ++k) {
        const std::size_t i = mRepulsive[k];
        if (!mObjects[i].spec->isDynamic) continue;
        // The farthest any corner of the root moves over the frame bounds every point's motion.
        const Transform& a = mStatesAtFrameStart[i].pose;
        const Transform& b = mStates[i].pose;
        const BBoxd& root = mObjects[i].field->bounds();
        double travel = 0.0;
        for (int corner = 0; corner < 8; ++corner) {
            const Vec3d c = boxCorner(root, corner);
            travel = std::max(travel, (b.worldFromObject(c) - a.worldFromObject(c)).length());
        }
        mFieldSpeed[k] = travel / (t1 - t0);
    }
}

bool Simulator::resolveContacts(const Vec3d& from, Vec3d& x, Vec3d& v, double t, double dt,
                                std::vector<MeshDistance::Accessor>& accessors, std::vector<double>& lowerBounds) const
{
    bool touched = false;
    for (std::size_t k = 0; k < mContact.size(); ++k) {
        const std::size_t i = mContact[k];
        const MeshDistance& distance = *mObjects[i].distance;
        const bool isDynamic = mObjects[i].spec->isDynamic, inWorld = mWorldIsObject[i];
        double& bound = lowerBounds[k];
        const double skin = distance.voxelSize();
        // Most substeps of a cloud over terrain: a static surface in world
        // space whose carried bound clears the path, decided as below but
        // before any pose is looked up (one path for all, with the poses
        // made only for dynamic objects, costs more on every substep).
        // The particle loop makes this test before calling, for all
        // surfaces at once when every one is such.
        if (!isDynamic && inWorld) {
            const double travel = readChangeBound(x - from);
            if (bound - travel >= 0.5 * skin) {
                bound -= travel;
                continue;
            }
        }
        Transform moving[2];
        const Transform& before = isDynamic ? (moving[0] = poseAt(i, t)) : mStates[i].pose;
        const Transform& after = isDynamic ? (moving[1] = poseAt(i, t + dt)) : before;
        // The substep's path as the object sees it, sampled a voxel apart.
        const Vec3d a = inWorld ? from : objectPoint(before, from), b = inWorld ? x : objectPoint(after, x);
        // A path starting this far out cannot come within half a voxel (most
        // substeps, at one read instead of one per voxel of the path, or none
        // while a static object's carried bound is far enough out).
        const double travel = readChangeBound(b - a);
        if (isDynamic) bound = -std::numeric_limits<double>::infinity(); // it moved: unknown
        // What the rest would decide, at no read.
        if (bound - travel >= 0.5 * skin) {
            bound -= travel;
            continue;
        }
        BBoxd path(a, a);
        path.expand(b);
        if (!path.hasOverlap(distance.reach())) {
            bound -= travel;
            continue;
        }
        bound = distance.distance(accessors[k], a);
        bound -= travel; // now a bound at b
        if (bound >= 0.5 * skin) continue;
        const int samples = std::max(1, int(std::ceil((b - a).length() / skin)));
        int hit = -1;
        for (int s = 0; s <= samples && hit < 0; ++s)
            if (distance.distance(accessors[k], a + (b - a) * (double(s) / samples)) < 0.5 * skin) hit = s;
        if (hit < 0) continue;
        // A path that ends at or in the surface ends pushed out of it along
        // the gradient, so a particle pressed onto a slope slides along it;
        // one that went through and out again (a thin part) stops where it
        // reached the surface. One that began on or in it (rounding, or a
        // rotation sweeping over it) is pushed out too.
        const auto pushedOut = [&](Vec3d& point) {
            for (int iteration = 0; iteration < 8; ++iteration) {
                const double d = distance.distance(accessors[k], point);
                if (d >= 0.5 * skin) return true;
                const Vec3d normal = distance.gradient(accessors[k], point);
                if (normal.lengthSqr() < 1e-12) return false;
                point += normal.unitSafe() * (skin - d);
            }
            return distance.distance(accessors[k], point) >= 0.5 * skin;
        };
        const Vec3d beforeHit = a + (b - a) * (double(std::max(hit - 1, 0)) / samples);
        const bool endsAtSurface = distance.distance(accessors[k], b) < 0.5 * skin;
        Vec3d local = endsAtSurface ? b : beforeHit;
        // A path that ends deeper than the level set's inner band (a static
        // object's is three voxels) finds no gradient there: it stops where
        // it reached the surface instead.
        if (!pushedOut(local) && endsAtSurface) {
            local = beforeHit;
            pushedOut(local);
        }
        x = after.worldFromObject(local);
        // Moved off its path: every object's bound is unknown again.
        std::fill(lowerBounds.begin(), lowerBounds.end(), -std::numeric_limits<double>::infinity());
        const Vec3d normal = after.rotateToWorld(distance.gradient(accessors[k], local)).unitSafe();
        const Vec3d surfaceVelocity = (x - before.worldFromObject(local)) / dt;
        const double approach = (v - surfaceVelocity).dot(normal);
        if (approach < 0.0) v -= normal * approach;
        touched = true;
    }
    return touched;
}

bool Simulator::endsInside(const Vec3d& x, double t, std::vector<MeshDistance::Accessor>& accessors,
                           const std::vector<double>& lowerBounds) const
{
    for (std::size_t k = 0; k < mContact.size(); ++k) {
        if (lowerBounds[k] >= 0.0) continue; // outside, as a read would say
        const MeshDistance& distance = *mObjects[mContact[k]].distance;
        const Vec3d local = mWorldIsObject[mContact[k]] ? x : objectPoint(poseAt(mContact[k], t), x);
        if (distance.reach().isInside(local) && distance.distance(accessors[k], local) < 0.0) return true;
    }
    return false;
}

void Simulator::advanceParticles(double t0, double t1)
{
    // Re-sorted every few frames (particles drift little in between), so
    // that splats read them in order: see kSortInterval.
    if (mFrame % kSortInterval == 0) mParticles.sortSpatially(mDomain);
    const std::size_t n = mParticles.size();
    std::vector<uint8_t> alive(n, 1);
    // Counted per task and summed (sums and a maximum: the same for any split).
    std::mutex countsMutex;
    const double cfl = mSetup.solver.cfl;
    measureFieldSpeeds(t0, t1);
    // No cell is finer than this, so a substep starting in one cannot step
    // into finer cells, and without moving fields none sweeps faster over it.
    const double finestCell = std::min(mFinestCell, LocalBound{}.cell);
    const bool fieldsMove = std::any_of(mFieldSpeed.begin(), mFieldSpeed.end(), [](double speed) { return speed > 0.0; });
    const std::size_t contacts = mContact.size();
    if (mKeptBounds.id.size() != n || mKeptBounds.bound.size() != n * contacts) // a new cloud: nothing carried
        mKeptBounds = {std::vector<uint32_t>(n), std::vector<double>(n * contacts, -std::numeric_limits<double>::infinity())};

    // Static surfaces in world space (terrain, as a rule) clear most
    // substeps by their carried bounds alone: decided in the loop, before
    // resolveContacts, when every contact surface is one.
    std::vector<double> halfSkins;
    bool contactsStaticInWorld = true;
    for (const std::size_t i : mContact) {
        halfSkins.push_back(0.5 * mObjects[i].distance->voxelSize());
        contactsStaticInWorld = contactsStaticInWorld && mWorldIsObject[i];
    }

    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const tbb::blocked_range<std::size_t>& range) {
        std::vector<RepulsionField::Accessor> accessors;
        for (const std::size_t i : mRepulsive) accessors.push_back(mObjects[i].field->accessor());
        std::vector<MeshDistance::Accessor> distances;
        for (const std::size_t i : mContact) distances.push_back(mObjects[i].distance->accessor());
        std::vector<double> lowerBounds(mContact.size());
        StepStats counts;
        DragFactors drag;
        for (std::size_t p = range.begin(); p != range.end(); ++p) {
            const CloudSettings& cloud = mSetup.clouds[mParticles.cloud[p]];
            const AccelerationFields& fields = mCloudFields[mParticles.cloud[p]];
            Vec3d x(mParticles.position[p]), v(mParticles.velocity[p]);
            double t = t0;
            uint32_t steps = 0;
            const bool boundsKept = mKeptBounds.id[p] == mParticles.id[p];
            for (std::size_t k = 0; k < contacts; ++k)
                lowerBounds[k] = boundsKept ? mKeptBounds.bound[p * contacts + k] : -std::numeric_limits<double>::infinity();
            while (t < t1) {
                const FieldsAt at = fieldsAt(x, t, cloud.mass, accessors.data(), true);
                const Vec3d a = fieldAcceleration(fields, x, t) + at.acceleration;
                // In a potential flow's band the particle moves with the flow:
                // at the terminal velocity of what acts on it, without inertia.
                const bool carried = at.inFlow;
                if (carried) v = a / cloud.drag;
                // Each move stays within cfl of the cells around the particle,
                // counting the motion of fields sweeping over it; where the
                // step would end in finer cells, those bound it too.
                const LocalBound& here = at.bound;
                double dt = stepWithin(t1 - t, v, here.fieldSpeed, a, cfl * here.cell);
                if ((here.cell > finestCell || fieldsMove) && !at.sameBound.isInside(x + v * dt)) {
                    const LocalBound there = fieldsAt(x + v * dt, t + dt, cloud.mass, accessors.data(), false).bound;
                    if (there.cell < here.cell || there.fieldSpeed > here.fieldSpeed)
                        dt = stepWithin(dt, v, std::max(here.fieldSpeed, there.fieldSpeed), a,
                                        cfl * std::min(here.cell, there.cell));
                }
                dt = std::max(dt, 1e-9 * (t1 - t0));
                const Vec3d from = x;
                if (carried) x += v * dt;
                else {
                    drag.update(cloud.drag, dt);
                    drag.step(x, v, a, dt);
                }
                if (!mContact.empty()) {
                    // resolveContacts' first test, for all surfaces at once.
                    const double travel = readChangeBound(x - from);
                    bool cleared = contactsStaticInWorld;
                    for (std::size_t k = 0; k < contacts && cleared; ++k) cleared = lowerBounds[k] - travel >= halfSkins[k];
                    if (cleared)
                        for (double& bound : lowerBounds) bound -= travel;
                    else if (resolveContacts(from, x, v, t, dt, distances, lowerBounds)) ++counts.contacts;
                    // A bound at or above zero says outside, as a read would: most substeps read nothing.
                    const bool mayEndInside =
                        std::any_of(lowerBounds.begin(), lowerBounds.end(), [](double bound) { return !(bound >= 0.0); });
                    if (mayEndInside && endsInside(x, t + dt, distances, lowerBounds)) ++counts.endedInside;
                }
                t = (t1 - t <= dt) ? t1 : t + dt;
                ++steps;
                if (!mDomain.isInside(x)) {
                    alive[p] = 0;
                    ++counts.removed;
                    break;
                }
            }
            mParticles.position[p] = Vec3f(x);
            mParticles.velocity[p] = Vec3f(v);
            // The next frame starts from the stored (rounded) position: its
            // bounds are that much lower.
            const double rounding = readChangeBound(Vec3d(mParticles.position[p]) - x);
            mKeptBounds.id[p] = mParticles.id[p];
            for (std::size_t k = 0; k < contacts; ++k) mKeptBounds.bound[p * contacts + k] = lowerBounds[k] - rounding;
            mParticles.peak[p] = std::max(mParticles.peak[p], mParticles.position[p].y());
            counts.substeps += steps;
            counts.maxSubsteps = std::max(counts.maxSubsteps, steps);
        }
        const std::lock_guard<std::mutex> lock(countsMutex);
        mLastStep.substeps += counts.substeps;
        mLastStep.maxSubsteps = std::max(mLastStep.maxSubsteps, counts.maxSubsteps);
        mLastStep.contacts += counts.contacts;
        mLastStep.endedInside += counts.endedInside;
        mLastStep.removed += counts.removed;
    });

    mRemovedTotal += mLastStep.removed;
    if (mLastStep.removed > 0) {
        mParticles.keep(alive);
        keepFlagged(mKeptBounds.id, alive);
        keepFlagged(mKeptBounds.bound, alive, contacts);
    }
}

void Simulator::updateRestPositions()
{
    const int period = mSetup.solver.restPeriod;
    if (period == 0) return;
    // Each rest is reset where its weight is zero: `rest` at the period's
    // start, rest2 half a period later; the weights ramp linearly between.
    const int age = (mFrame - mSetup.firstFrame) % period;
    if (age == 0) mParticles.rest = mParticles.position;
    if (age == period / 2 || mParticles.rest2.empty()) mParticles.rest2 = mParticles.position;
    mParticles.rest2Weight = float(std::abs(1.0 - 2.0 * age / period));
}

} // namespace vfield
