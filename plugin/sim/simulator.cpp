#include <vfield/sim/simulator.h>

#include <vfield/core/error.h>
#include <vfield/core/noise.h>

#include <openvdb/tools/Composite.h>
#include <openvdb/tools/GridTransformer.h>
#include <openvdb/tools/Interpolation.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <random>

namespace vfield {

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Frames between spatial sorts of the particles: a sort costs about one
/// frame's advection, and in a few frames particles drift too little to spoil
/// the order for the density splat, whose speed depends on it (10x).
constexpr int kSortInterval = 8;

/// Uniform double in [0, 1) from a 64-bit generator (the standard's
/// distributions differ between libraries; this does not).
double unitRandom(std::mt19937_64& random) { return double(random() >> 11) * (1.0 / 9007199254740992.0); }

/// A point of the cloud's shape, uniform: rejection sampling from the box
/// around it. With billow the shape's surface is pulled in by up to that
/// fraction of its radii where the billow noise is high, so the cloud is
/// lumps with creases between (every point within 1 - billow of the centre is
/// kept, so the loop ends).
Vec3d samplePointIn(const CloudSpec& cloud, const GradientNoise& noise, std::mt19937_64& random)
{
    const double billowSize =
        cloud.billowSize > 0.0 ? cloud.billowSize : std::min({cloud.radii[0], cloud.radii[1], cloud.radii[2]}) / 3.0;
    for (;;) {
        const Vec3d u(2 * unitRandom(random) - 1, 2 * unitRandom(random) - 1, 2 * unitRandom(random) - 1);
        const Vec3d offset(u[0] * cloud.radii[0], u[1] * cloud.radii[1], u[2] * cloud.radii[2]);
        // The shape's norm: 1 on its surface.
        const double r =
            cloud.shape == CloudSpec::Shape::Box ? std::max({std::abs(u[0]), std::abs(u[1]), std::abs(u[2])}) : u.length();
        if (r > 1.0) continue;
        if (cloud.billow > 0.0 && r > 1.0 - cloud.billow * double(billow(noise, Vec3f(offset / billowSize), {3, 2.0, 0.5})))
            continue;
        return cloud.center + offset;
    }
}

/// The longest dt for which |v| dt + |a| dt^2 <= reach (the substep's travel bound).
double stepLimit(double speed, double acceleration, double reach)
{
    if (acceleration <= 0.0) return speed > 0.0 ? reach / speed : std::numeric_limits<double>::infinity();
    return 2.0 * reach / (speed + std::sqrt(speed * speed + 4.0 * acceleration * reach));
}

/// One substep of dv/dt = a - drag v with a held constant: the velocity
/// relaxes exactly towards the terminal velocity a / drag, as exp(-drag dt),
/// so any drag is stable (an explicit step overshoots once drag dt > 1); the
/// position moves with the new velocity (semi-implicit Euler, which reacts to
/// repulsion within the substep). With no drag this is v += a dt, x += v dt.
/// The travel, |v_new| dt, is at most |v| dt + |a| dt^2: what stepLimit bounds.
void integrateWithDrag(Vec3d& x, Vec3d& v, const Vec3d& a, double drag, double dt)
{
    // (1 - e^-h) / h for h = drag dt, by its series where the closed form loses precision.
    const double h = drag * dt;
    const double relaxed = h < 1e-5 ? 1.0 - h / 2.0 + h * h / 6.0 : -std::expm1(-h) / h;
    v = v * std::exp(-h) + a * (dt * relaxed);
    x += v * dt;
}

/// Turns a dynamic object over a substep of dt (0: at once): heading at once
/// to its velocity (nose +x, up +y), pitch towards the velocity's and, with
/// bank, roll into the turn from the sideways acceleration, each at most at
/// its rate. Roll follows the acceleration, which jumps tenfold at a field's
/// surface leaves: unlimited, it flipped sign within a substep.
void turn(DynamicState& state, const Vec3d& acceleration, const ObjectSpec& spec, double dt)
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

Quatd slerp(const Quatd& a, Quatd b, double t)
{
    double dot = a.x() * b.x() + a.y() * b.y() + a.z() * b.z() + a.w() * b.w();
    if (dot < 0) {
        b = Quatd(-b.x(), -b.y(), -b.z(), -b.w());
        dot = -dot;
    }
    if (dot > 0.9995) { // nearly equal: normalized lerp
        const Quatd q(a.x() + t * (b.x() - a.x()), a.y() + t * (b.y() - a.y()), a.z() + t * (b.z() - a.z()),
                      a.w() + t * (b.w() - a.w()));
        return q.unit();
    }
    const double theta = std::acos(dot), s = std::sin(theta);
    const double wa = std::sin((1 - t) * theta) / s, wb = std::sin(t * theta) / s;
    return Quatd(wa * a.x() + wb * b.x(), wa * a.y() + wb * b.y(), wa * a.z() + wb * b.z(), wa * a.w() + wb * b.w());
}

} // namespace

Simulator::Simulator(const SimulationSetup& setup) : mSetup(setup), mFrame(setup.firstFrame)
{
    openvdb::initialize();
    setup.validate();
    int64_t total = 0;
    for (const CloudSpec& c : setup.clouds) total += c.count;

    // What a potential flow deflects: the wind every cloud feels everywhere.
    Vec3d cloudsWind(0.0);
    if (!setup.clouds.empty())
        for (const UniformFieldSpec& field : setup.fields)
            if (!field.box && std::all_of(setup.clouds.begin(), setup.clouds.end(),
                                          [&](const CloudSpec& cloud) { return field.acts(cloud.name); }))
                cloudsWind += field.acceleration;

    // Meshes and fields, objects in parallel (each build is parallel too).
    mObjects.resize(mSetup.objects.size());
    tbb::parallel_for(std::size_t(0), mObjects.size(), [&](std::size_t i) {
        SimObject& object = mObjects[i];
        object.spec = &mSetup.objects[i];
        object.mesh = makeMesh(object.spec->mesh, &object.loadReport);
        if (object.spec->repulsion) {
            const auto start = std::chrono::steady_clock::now();
            object.field =
                RepulsionField::build(object.mesh, *object.spec->repulsion, object.spec->transform.rotateToObject(cloudsWind));
            object.fieldSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        }
        if (object.spec->isDynamic) {
            for (std::size_t t = 0; t < object.mesh.triangleCount(); ++t) object.centroids.push_back(object.mesh.centroid(t));
            for (const Vec3f& p : object.mesh.points) object.radius = std::max(object.radius, double(p.length()));
            if (analyzeTopology(object.mesh).isClosed()) {
                const BBoxd box = object.mesh.bounds();
                const double extent = box.extents()[box.maxExtent()];
                // Wider bands cost cubically in voxels (a margin of 20 took 285 voxels
                // and most of a four-aircraft run) and serve only measurement.
                const double band =
                    object.field ? std::min(0.5 * (object.field->rootSide() - extent), 0.5 * extent) : 0.1 * extent;
                object.distance = std::make_shared<MeshDistance>(object.mesh, extent / 128.0, band, 0.5 * extent);
            }
        }
    });

    mStates.resize(mObjects.size());
    BBoxd domain;
    mFinestCell = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < mObjects.size(); ++i) {
        const SimObject& object = mObjects[i];
        mStates[i].pose = object.spec->transform;
        mStates[i].velocity = object.spec->isDynamic ? object.spec->velocity : Vec3d(0.0);
        if (object.spec->isDynamic) turn(mStates[i], Vec3d(0.0), *object.spec, 0.0);
        if (object.distance) mContact.push_back(i);
        if (!object.field) continue;
        if (object.field->isFlow()) mFlow.push_back(mRepulsive.size());
        mRepulsive.push_back(i);
        const double scale = object.spec->transform.scale;
        mFinestCell = std::min(mFinestCell, object.field->finestCellSize() * scale);
        domain.expand(object.spec->transform.worldBounds(object.field->bounds()));
    }
    if (!std::isfinite(mFinestCell)) mFinestCell = 1.0; // no fields: steps bounded by the unit length

    // Clouds: each from its own seed stream, mixed with the scene's seed.
    mParticles.reserve(std::size_t(total));
    uint32_t nextId = 0;
    for (std::size_t c = 0; c < mSetup.clouds.size(); ++c) {
        const CloudSpec& cloud = mSetup.clouds[c];
        std::mt19937_64 random(mSetup.seed * 0x9e3779b97f4a7c15ull ^ (cloud.seed + 0x632be59bd9b4e019ull * (c + 1)));
        const GradientNoise puffs(cloud.seed);
        for (int64_t k = 0; k < cloud.count; ++k) {
            mParticles.position.emplace_back(samplePointIn(cloud, puffs, random));
            mParticles.velocity.emplace_back(cloud.velocity);
            mParticles.rest.push_back(mParticles.position.back());
            mParticles.id.push_back(nextId++);
            mParticles.radius.push_back(float(cloud.particleRadius));
            mParticles.cloud.push_back(uint16_t(c));
        }
        domain.expand(BBoxd(cloud.center - cloud.radii, cloud.center + cloud.radii));
    }
    mDomain = mSetup.options.domain.value_or(domain);
    mStatesAtFrameStart = mStates;
    updateRestPositions();

    mObjectFields.resize(mObjects.size());
    mCloudFields.resize(mSetup.clouds.size());
    for (std::size_t f = 0; f < mSetup.fields.size(); ++f) {
        const UniformFieldSpec& field = mSetup.fields[f];
        for (std::size_t i = 0; i < mObjects.size(); ++i)
            if (field.acts(mSetup.objects[i].name)) mObjectFields[i].push_back(f);
        for (std::size_t c = 0; c < mSetup.clouds.size(); ++c)
            if (field.acts(mSetup.clouds[c].name)) mCloudFields[c].push_back(f);
    }
}

Vec3d Simulator::uniformAcceleration(const std::vector<std::size_t>& fields, const Vec3d& p) const
{
    Vec3d a(0.0);
    for (const std::size_t f : fields) a += mSetup.fields[f].accelerationAt(p);
    return a;
}

std::vector<std::string> Simulator::meshReports() const
{
    std::vector<std::string> lines;
    for (const SimObject& object : mObjects)
        for (const std::string& line : object.loadReport.lines(object.spec->mesh.path)) lines.push_back(line);
    return lines;
}

Transform Simulator::poseAt(std::size_t object, double time) const
{
    if (!mObjects[object].spec->isDynamic) return mStates[object].pose;
    const double t0 = mSetup.frameTime(mFrame - 1), t1 = mSetup.frameTime(mFrame);
    const double s = t1 > t0 ? std::clamp((time - t0) / (t1 - t0), 0.0, 1.0) : 1.0;
    const Transform& a = mStatesAtFrameStart[object].pose;
    const Transform& b = mStates[object].pose;
    Transform pose = b;
    pose.translation = a.translation + (b.translation - a.translation) * s;
    pose.rotation = slerp(a.rotation, b.rotation, s);
    return pose;
}

Vec3d Simulator::repulsion(const Vec3d& p, double time, double mass, openvdb::Vec3SGrid::ConstAccessor* accessors) const
{
    Vec3d force(0.0), flow(0.0);
    for (std::size_t k = 0; k < mRepulsive.size(); ++k) {
        const std::size_t i = mRepulsive[k];
        const SimObject& object = mObjects[i];
        const Transform pose = object.spec->isDynamic ? poseAt(i, time) : mStates[i].pose;
        const bool rotated = isRotated(pose);
        const Vec3d local = objectPoint(pose, p);
        if (!object.field->bounds().isInside(local)) continue;
        const openvdb::Vec3d index = object.field->force()->transform().worldToIndex(local);
        openvdb::Vec3s f;
        if (mSetup.options.sampling == SimulationOptions::Sampling::Nearest)
            openvdb::tools::PointSampler::sample(accessors[k], index, f);
        else openvdb::tools::BoxSampler::sample(accessors[k], index, f);
        const Vec3d world = rotated ? pose.rotateToWorld(Vec3d(f)) : Vec3d(f);
        (object.field->isFlow() ? flow : force) += world;
    }
    return force / mass + flow;
}

void Simulator::advanceDynamicObjects(double t0, double t1, const std::function<void()>& afterSubstep)
{
    std::vector<std::size_t> dynamic;
    for (std::size_t i = 0; i < mObjects.size(); ++i)
        if (mObjects[i].spec->isDynamic) dynamic.push_back(i);
    if (dynamic.empty()) return;

    const double reach = mSetup.options.cfl * mFinestCell;
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
            const ObjectSpec& spec = *mObjects[i].spec;
            const DynamicState& state = mStates[i];
            Vec3d a = uniformAcceleration(mObjectFields[i], state.pose.translation);
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
            const ObjectSpec& spec = *mObjects[dynamic[d]].spec;
            const Vec3d netAcceleration = acceleration[d] - spec.drag * state.velocity;
            integrateWithDrag(state.pose.translation, state.velocity, acceleration[d], spec.drag, dt);
            turn(state, netAcceleration, spec, dt);
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

Simulator::LocalBound Simulator::localBound(const Vec3d& p, double time, openvdb::Int32Grid::ConstAccessor* levels) const
{
    LocalBound bound;
    bool inAnyField = false;
    double cell = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < mRepulsive.size(); ++k) {
        const std::size_t i = mRepulsive[k];
        const SimObject& object = mObjects[i];
        const Transform pose = object.spec->isDynamic ? poseAt(i, time) : mStates[i].pose;
        const Vec3d local = objectPoint(pose, p);
        const RepulsionField& field = *object.field;
        // A moving field reaches whatever its root sweeps over during the frame.
        const double sweep = k < mFieldSpeed.size() ? mFieldSpeed[k] * mFieldFrameTime / pose.scale : 0.0;
        BBoxd reach = field.bounds();
        reach.expand(sweep);
        if (!reach.isInside(local)) continue;
        inAnyField = true;
        // The leaf's level from the voxel holding p: finest-leaf voxels never straddle a leaf.
        const int level =
            field.bounds().isInside(local)
                ? std::max(levels[k].getValue(openvdb::Coord::round(field.level()->transform().worldToIndex(local))), 1)
                : field.depth();
        cell = std::min(cell, field.cellSize(level) * pose.scale);
        if (k < mFieldSpeed.size()) bound.fieldSpeed = std::max(bound.fieldSpeed, mFieldSpeed[k]);
    }
    if (inAnyField) bound.cell = cell;
    return bound;
}

bool Simulator::resolveContacts(const Vec3d& from, Vec3d& x, Vec3d& v, double t, double dt,
                                std::vector<MeshDistance::Accessor>& accessors) const
{
    bool touched = false;
    for (std::size_t k = 0; k < mContact.size(); ++k) {
        const std::size_t i = mContact[k];
        const MeshDistance& distance = *mObjects[i].distance;
        const Transform before = poseAt(i, t), after = poseAt(i, t + dt);
        // The substep's path as the object sees it, sampled a voxel apart.
        const Vec3d a = before.objectFromWorld(from), b = after.objectFromWorld(x);
        BBoxd path(a, a);
        path.expand(b);
        if (!path.hasOverlap(distance.reach())) continue;
        const double skin = distance.voxelSize();
        const int samples = std::max(1, int(std::ceil((b - a).length() / skin)));
        int hit = -1;
        for (int s = 0; s <= samples && hit < 0; ++s)
            if (distance.distance(accessors[k], a + (b - a) * (double(s) / samples)) < 0.5 * skin) hit = s;
        if (hit < 0) continue;
        // Stop where the path reached the surface; a particle that began on
        // or in it (rounding, or a rotation sweeping over it) is pushed out
        // along the gradient.
        Vec3d local = a + (b - a) * (double(std::max(hit - 1, 0)) / samples);
        for (int iteration = 0; iteration < 8; ++iteration) {
            const double d = distance.distance(accessors[k], local);
            if (d >= 0.5 * skin) break;
            const Vec3d normal = distance.gradient(accessors[k], local);
            if (normal.lengthSqr() < 1e-12) break;
            local += normal.unitSafe() * (skin - d);
        }
        x = after.worldFromObject(local);
        const Vec3d normal = after.rotateToWorld(distance.gradient(accessors[k], local)).unitSafe();
        const Vec3d surfaceVelocity = (x - before.worldFromObject(local)) / dt;
        const double approach = (v - surfaceVelocity).dot(normal);
        if (approach < 0.0) v -= normal * approach;
        touched = true;
    }
    return touched;
}

bool Simulator::inFlow(const Vec3d& p, openvdb::Int32Grid::ConstAccessor* levels) const
{
    for (const std::size_t k : mFlow) {
        const RepulsionField& field = *mObjects[mRepulsive[k]].field;
        const Vec3d local = objectPoint(mStates[mRepulsive[k]].pose, p); // flows are static
        if (field.bounds().isInside(local) &&
            levels[k].getValue(openvdb::Coord::round(field.level()->transform().worldToIndex(local))) > 0)
            return true;
    }
    return false;
}

bool Simulator::endsInside(const Vec3d& x, double t, std::vector<MeshDistance::Accessor>& accessors) const
{
    for (std::size_t k = 0; k < mContact.size(); ++k) {
        const MeshDistance& distance = *mObjects[mContact[k]].distance;
        const Vec3d local = poseAt(mContact[k], t).objectFromWorld(x);
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
    std::vector<uint32_t> substepsOf(n, 0), contactsOf(n, 0), insideOf(n, 0);
    const double cfl = mSetup.options.cfl;
    measureFieldSpeeds(t0, t1);

    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const tbb::blocked_range<std::size_t>& range) {
        std::vector<openvdb::Vec3SGrid::ConstAccessor> accessors;
        std::vector<openvdb::Int32Grid::ConstAccessor> levels;
        for (const std::size_t i : mRepulsive) {
            accessors.push_back(mObjects[i].field->force()->getConstAccessor());
            levels.push_back(mObjects[i].field->level()->getConstAccessor());
        }
        std::vector<MeshDistance::Accessor> distances;
        for (const std::size_t i : mContact) distances.push_back(mObjects[i].distance->accessor());
        for (std::size_t p = range.begin(); p != range.end(); ++p) {
            const CloudSpec& cloud = mSetup.clouds[mParticles.cloud[p]];
            const std::vector<std::size_t>& fields = mCloudFields[mParticles.cloud[p]];
            Vec3d x(mParticles.position[p]), v(mParticles.velocity[p]);
            double t = t0;
            uint32_t steps = 0;
            while (t < t1) {
                Vec3d a = uniformAcceleration(fields, x);
                a += repulsion(x, t, cloud.mass, accessors.data());
                // In a potential flow's band the particle moves with the flow:
                // at the terminal velocity of what acts on it, without inertia.
                const bool carried = inFlow(x, levels.data());
                if (carried) v = a / cloud.drag;
                // Each move stays within cfl of the cells around the particle,
                // counting the motion of fields sweeping over it; where the
                // step would end in finer cells, those bound it too.
                const LocalBound here = localBound(x, t, levels.data());
                double dt = std::min(t1 - t, stepLimit(v.length() + here.fieldSpeed, a.length(), cfl * here.cell));
                const LocalBound there = localBound(x + v * dt, t + dt, levels.data());
                if (there.cell < here.cell || there.fieldSpeed > here.fieldSpeed)
                    dt = std::min(dt, stepLimit(v.length() + std::max(here.fieldSpeed, there.fieldSpeed), a.length(),
                                                cfl * std::min(here.cell, there.cell)));
                dt = std::max(dt, 1e-9 * (t1 - t0));
                const Vec3d from = x;
                if (carried) x += v * dt;
                else integrateWithDrag(x, v, a, cloud.drag, dt);
                if (!mContact.empty()) {
                    if (resolveContacts(from, x, v, t, dt, distances)) ++contactsOf[p];
                    if (endsInside(x, t + dt, distances)) ++insideOf[p];
                }
                t = (t1 - t <= dt) ? t1 : t + dt;
                ++steps;
                if (!mDomain.isInside(x)) {
                    alive[p] = 0;
                    break;
                }
            }
            mParticles.position[p] = Vec3f(x);
            mParticles.velocity[p] = Vec3f(v);
            substepsOf[p] = steps;
        }
    });

    for (std::size_t p = 0; p < n; ++p) {
        mLastStep.substeps += substepsOf[p];
        mLastStep.maxSubsteps = std::max(mLastStep.maxSubsteps, substepsOf[p]);
        mLastStep.contacts += contactsOf[p];
        mLastStep.endedInside += insideOf[p];
        if (!alive[p]) ++mLastStep.removed;
    }
    mRemovedTotal += mLastStep.removed;
    if (mLastStep.removed > 0) mParticles.keep(alive);
}

void Simulator::advanceFrame(const std::function<void()>& afterDynamicSubstep)
{
    const double t0 = mSetup.frameTime(mFrame), t1 = mSetup.frameTime(mFrame + 1);
    mLastStep = {};
    mStatesAtFrameStart = mStates;
    advanceDynamicObjects(t0, t1, afterDynamicSubstep);
    ++mFrame; // poseAt interpolates between the two frames' poses
    advanceParticles(t0, t1);
    updateRestPositions();
}

void Simulator::updateRestPositions()
{
    const int period = mSetup.options.restPeriod;
    if (period == 0) return;
    // Each rest is reset where its weight is zero: `rest` at the period's
    // start, rest2 half a period later; the weights ramp linearly between.
    const int age = (mFrame - mSetup.firstFrame) % period;
    if (age == 0) mParticles.rest = mParticles.position;
    if (age == period / 2 || mParticles.rest2.empty()) mParticles.rest2 = mParticles.position;
    mParticles.rest2Weight = float(std::abs(1.0 - 2.0 * age / period));
}

openvdb::Vec3SGrid::Ptr Simulator::staticForceGrid() const
{
    openvdb::Vec3SGrid::Ptr combined;
    for (const std::size_t i : mRepulsive) {
        const SimObject& object = mObjects[i];
        if (object.spec->isDynamic) continue;
        const Transform& pose = mStates[i].pose;
        // Forces rotate with the object; positions follow its transform.
        openvdb::Vec3SGrid::Ptr world = object.field->force()->deepCopy();
        if (!pose.rotation.eq(Quatd::identity()))
            for (auto it = world->tree().beginValueOn(); it; ++it) it.setValue(openvdb::Vec3s(pose.rotateToWorld(Vec3d(*it))));
        world->transform().postMult(pose.matrix());
        if (!combined) {
            combined = world;
            continue;
        }
        openvdb::Vec3SGrid::Ptr resampled = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
        resampled->setTransform(combined->transform().copy());
        openvdb::tools::resampleToMatch<openvdb::tools::PointSampler>(*world, *resampled);
        openvdb::tools::compSum(*combined, *resampled);
    }
    if (!combined) combined = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    combined->setName("force");
    return combined;
}

namespace {

template<typename T>
void put(std::string& out, const T& value)
{
    out.append(reinterpret_cast<const char*>(&value), sizeof value);
}

template<typename T>
void putVector(std::string& out, const std::vector<T>& values)
{
    put(out, uint64_t(values.size()));
    out.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

class Reader {
public:
    explicit Reader(const std::string& bytes) : mBytes(bytes) {}
    template<typename T>
    T get()
    {
        T value;
        need(sizeof value);
        std::memcpy(&value, mBytes.data() + mAt, sizeof value);
        mAt += sizeof value;
        return value;
    }
    template<typename T>
    void getVector(std::vector<T>& values)
    {
        const auto n = get<uint64_t>();
        need(n * sizeof(T));
        values.resize(n);
        std::memcpy(values.data(), mBytes.data() + mAt, n * sizeof(T));
        mAt += n * sizeof(T);
    }
    bool atEnd() const { return mAt == mBytes.size(); }

private:
    void need(uint64_t n) const
    {
        if (n > mBytes.size() - mAt) throw ValueError("the saved simulation state is truncated");
    }
    const std::string& mBytes;
    std::size_t mAt = 0;
};

constexpr uint64_t kStateMagic = 0x3374617473646676ull; // "vfdstat3"

} // namespace

std::string Simulator::serializeState() const
{
    std::string out;
    put(out, kStateMagic);
    put(out, int32_t(mFrame));
    put(out, mRemovedTotal);
    put(out, uint64_t(mStates.size()));
    for (const DynamicState& s : mStates) {
        put(out, s.pose.translation);
        put(out, s.pose.rotation);
        put(out, s.pose.scale);
        put(out, s.velocity);
        put(out, s.roll);
        put(out, s.pitch);
    }
    putVector(out, mParticles.position);
    putVector(out, mParticles.velocity);
    putVector(out, mParticles.rest);
    putVector(out, mParticles.rest2);
    putVector(out, mParticles.id);
    putVector(out, mParticles.radius);
    putVector(out, mParticles.cloud);
    return out;
}

void Simulator::restoreState(const std::string& bytes)
{
    Reader in(bytes);
    if (in.get<uint64_t>() != kStateMagic) throw ValueError("not a vfield simulation state");
    const int frame = in.get<int32_t>();
    const auto removed = in.get<uint64_t>();
    if (in.get<uint64_t>() != mStates.size()) throw ValueError("the saved state is of another scene (object count)");
    std::vector<DynamicState> states(mStates.size());
    for (DynamicState& s : states) {
        s.pose.translation = in.get<Vec3d>();
        s.pose.rotation = in.get<Quatd>();
        s.pose.scale = in.get<double>();
        s.velocity = in.get<Vec3d>();
        s.roll = in.get<double>();
        s.pitch = in.get<double>();
    }
    ParticleSet particles;
    in.getVector(particles.position);
    in.getVector(particles.velocity);
    in.getVector(particles.rest);
    in.getVector(particles.rest2);
    in.getVector(particles.id);
    in.getVector(particles.radius);
    in.getVector(particles.cloud);
    const std::size_t n = particles.size();
    if (!in.atEnd() || particles.velocity.size() != n || particles.rest.size() != n ||
        particles.rest2.size() != (mSetup.options.restPeriod == 0 ? 0 : n) || particles.id.size() != n ||
        particles.radius.size() != n || particles.cloud.size() != n)
        throw ValueError("the saved simulation state is inconsistent");
    for (const uint16_t c : particles.cloud)
        if (c >= mSetup.clouds.size()) throw ValueError("the saved state is of another scene (cloud index)");
    if (frame < mSetup.firstFrame || frame > mSetup.lastFrame) throw ValueError("the saved state's frame is out of range");
    mFrame = frame;
    mRemovedTotal = removed;
    mStates = std::move(states);
    mStatesAtFrameStart = mStates;
    mParticles = std::move(particles);
    updateRestPositions();
}

} // namespace vfield
