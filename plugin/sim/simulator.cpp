#include <vfield/sim/simulator.h>

#include <vfield/core/error.h>
#include <vfield/sim/emission.h>

#include <openvdb/tools/Composite.h>
#include <openvdb/tools/GridTransformer.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>

namespace vfield {

Simulator::Simulator(const SimulationSettings& setup, const Preparing& preparing) : mSetup(setup), mFrame(setup.firstFrame)
{
    std::mutex reporting;
    const auto report = [&](const std::string& step) {
        if (!preparing) return;
        const std::lock_guard<std::mutex> lock(reporting);
        preparing(step);
    };
    openvdb::initialize();
    setup.validate();

    // What a potential flow deflects: the wind every cloud feels everywhere.
    Vec3d cloudsWind(0.0);
    if (!setup.clouds.empty())
        for (const UniformFieldSettings& field : setup.fields)
            if (!field.box && std::all_of(setup.clouds.begin(), setup.clouds.end(),
                                          [&](const CloudSettings& cloud) { return field.acts(cloud.name); }))
                cloudsWind += field.acceleration;

    // Meshes and fields, objects in parallel (each build is parallel too).
    mObjects.resize(mSetup.objects.size());
    tbb::parallel_for(std::size_t(0), mObjects.size(), [&](std::size_t i) {
        SimObject& object = mObjects[i];
        object.spec = &mSetup.objects[i];
        const std::string& name = object.spec->name;
        const auto distanceProgress = [&](int percent) {
            report(name + ": exact distance field " + std::to_string(percent) + "%");
        };
        report(name + ": mesh");
        object.mesh = makeMesh(object.spec->mesh, &object.loadReport);
        if (object.spec->repulsion) {
            report(name + ": " + enumName(object.spec->repulsion->method) + " field of " +
                   std::to_string(object.mesh.triangleCount()) + " triangles");
            const auto start = std::chrono::steady_clock::now();
            object.field = RepulsionField::build(object.mesh, *object.spec->repulsion, mSetup.solver.sampling,
                                                 object.spec->transform.rotateToObject(cloudsWind),
                                                 [&](const std::string& step) { report(name + ": " + step); });
            object.fieldSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        }
        object.isClosed = analyzeTopology(object.mesh).isClosed();
        const BBoxd box = object.mesh.bounds();
        const double extent = box.extents()[box.maxExtent()];
        if (object.spec->isDynamic) {
            for (std::size_t t = 0; t < object.mesh.triangleCount(); ++t) object.centroids.push_back(object.mesh.centroid(t));
            for (const Vec3f& p : object.mesh.points) object.radius = std::max(object.radius, double(p.length()));
            if (object.isClosed) {
                report(name + ": exact distance field");
                // Wider bands cost cubically in voxels (a wide margin can take most
                // of a run's time) and serve only measurement.
                const double band =
                    object.field ? std::min(0.5 * (object.field->rootSide() - extent), 0.5 * extent) : 0.1 * extent;
                object.distance =
                    std::make_shared<MeshDistance>(object.mesh, extent / 128.0, band, 0.5 * extent, distanceProgress);
            }
        } else {
            // Half the finest leaf (a box's few triangles make large ones), at
            // most 1/256 of the extent, out to a tenth of the field's root,
            // three voxels deep: contact stops a path at the first sample
            // within half a voxel of the surface, so no path reaches deeper.
            // An open mesh's is only measured (its inside is undefined).
            double voxel = extent / 256.0;
            if (object.field) voxel = std::min(voxel, 0.5 * object.field->finestCellSize());
            const double reach = object.field ? 0.1 * object.field->rootSide() : 0.1 * extent;
            report(name + ": exact distance field");
            object.distance = std::make_shared<MeshDistance>(object.mesh, voxel, reach, 3.0 * voxel, distanceProgress);
        }
    });

    mStates.resize(mObjects.size());
    mWorldIsObject.resize(mObjects.size());
    BBoxd domain;
    mFinestCell = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < mObjects.size(); ++i) {
        const SimObject& object = mObjects[i];
        mStates[i].pose = object.spec->transform;
        mWorldIsObject[i] = !object.spec->isDynamic && object.spec->transform.isIdentity();
        mStates[i].velocity = object.spec->isDynamic ? object.spec->velocity : Vec3d(0.0);
        if (object.spec->isDynamic) turnToVelocity(mStates[i], Vec3d(0.0), *object.spec, 0.0);
        if (object.distance && object.isClosed) mContact.push_back(i);
        if (!object.field) continue;
        mRepulsive.push_back(i);
        const double scale = object.spec->transform.scale;
        mFinestCell = std::min(mFinestCell, object.field->finestCellSize() * scale);
        domain.expand(object.spec->transform.worldBounds(object.field->bounds()));
    }
    if (!std::isfinite(mFinestCell)) mFinestCell = 1.0; // no fields: steps bounded by the unit length

    // Clouds: each from its own seed stream, mixed with the scene's seed.
    if (!mSetup.clouds.empty()) report("clouds: emitting particles");
    mParticles = emitClouds(mSetup);
    makeEmitters();
    for (const CloudSettings& cloud : mSetup.clouds) domain.expand(BBoxd(cloud.center - cloud.radii, cloud.center + cloud.radii));
    mDomain = mSetup.solver.domain.value_or(domain);
    // Emitted in random order; splats run about ten times faster over
    // particles in spatial order, which advanceParticles keeps every few frames.
    mParticles.sortSpatially(mDomain);
    mStatesAtFrameStart = mStates;

    mObjectFields.resize(mObjects.size());
    mCloudFields.resize(mSetup.clouds.size());
    const auto add = [this](AccelerationFields& fields, std::size_t f) {
        // Summed now while every field so far acts everywhere and always alike: the sum a substep would make, in the same order.
        if (fields.rest.empty() && mSetup.fields[f].isUniformAndConstant()) fields.leadingSum += mSetup.fields[f].acceleration;
        else fields.rest.push_back(f);
    };
    for (std::size_t f = 0; f < mSetup.fields.size(); ++f) {
        const UniformFieldSettings& field = mSetup.fields[f];
        for (std::size_t i = 0; i < mObjects.size(); ++i)
            if (field.acts(mSetup.objects[i].name)) add(mObjectFields[i], f);
        for (std::size_t c = 0; c < mSetup.clouds.size(); ++c)
            if (field.acts(mSetup.clouds[c].name)) add(mCloudFields[c], f);
    }
    for (std::size_t f = 0; f < mSetup.turbulence.size(); ++f) {
        const TurbulenceSettings& turbulence = mSetup.turbulence[f];
        mTurbulence.emplace_back(turbulence, mSetup.firstFrame, mSetup.fps);
        for (std::size_t i = 0; i < mObjects.size(); ++i)
            if (turbulence.acts(mSetup.objects[i].name)) mObjectFields[i].turbulence.push_back(f);
        for (std::size_t c = 0; c < mSetup.clouds.size(); ++c)
            if (turbulence.acts(mSetup.clouds[c].name)) mCloudFields[c].turbulence.push_back(f);
    }

    // The preroll: the frames before the first, at earlier times, the
    // objects holding their first poses (poseAt interpolates between two
    // equal states). The particles rest where it leaves them, their peak
    // and origin heights there too (condensation counts from the first frame), sorted again.
    if (const int frames = mSetup.solver.preroll; frames > 0 && (mParticles.size() > 0 || !mEmitters.empty())) {
        report("clouds: preroll of " + std::to_string(frames) + " frames");
        const double first = mSetup.frameTime(mFrame);
        for (int frame = -frames; frame < 0; ++frame) {
            advanceParticles(first + frame / mSetup.fps, first + (frame + 1) / mSetup.fps);
            emitAndExpire(first + (frame + 1) / mSetup.fps);
        }
        mParticles.rest = mParticles.position;
        // Emitted particles keep the heights they were born at, which lift them to their condensation level.
        for (std::size_t p = 0; p < mParticles.size(); ++p)
            if (!mSetup.clouds[mParticles.cloud[p]].emission)
                mParticles.peak[p] = mParticles.origin[p] = mParticles.position[p].y();
        mParticles.sortSpatially(mDomain);
        mLastStep = {};
    }
    updateRestPositions();
}

std::vector<std::string> Simulator::meshReports() const
{
    std::vector<std::string> lines;
    for (const SimObject& object : mObjects)
        for (const std::string& line : object.loadReport.lines(object.spec->mesh.path)) lines.push_back(line);
    return lines;
}

void Simulator::advanceFrame(const std::function<void()>& afterDynamicSubstep)
{
    const double t0 = mSetup.frameTime(mFrame), t1 = mSetup.frameTime(mFrame + 1);
    mLastStep = {};
    mStatesAtFrameStart = mStates;
    if (mReplay) {
        for (std::size_t i = 0; i < mObjects.size(); ++i)
            if (mObjects[i].spec->isDynamic) mStates[i] = mReplay(mObjects[i], mFrame + 1);
    } else {
        advanceDynamicObjects(t0, t1, afterDynamicSubstep);
    }
    ++mFrame; // poseAt interpolates between the two frames' poses
    advanceParticles(t0, t1);
    emitAndExpire(t1);
    updateRestPositions();
}

void Simulator::keepParticles(const std::function<bool(uint32_t id)>& keep)
{
    mKeep = keep;
    std::vector<uint8_t> kept(mParticles.size());
    for (std::size_t p = 0; p < kept.size(); ++p) kept[p] = keep(mParticles.id[p]);
    mParticles.keep(kept);
}

void Simulator::makeEmitters()
{
    uint64_t nextId = mParticles.size();
    for (std::size_t c = 0; c < mSetup.clouds.size(); ++c) {
        const CloudSettings& cloud = mSetup.clouds[c];
        if (!cloud.emission) continue;
        const std::string key = "clouds/" + std::to_string(c) + "/emission/object";
        const TriangleMesh* mesh = nullptr;
        mEmitterObjects.push_back(-1);
        if (cloud.emission->from == EmissionSource::Surface || cloud.emission->from == EmissionSource::Inside) {
            // validate() made sure that it names one.
            const auto named = std::find_if(mObjects.begin(), mObjects.end(),
                                            [&](const SimObject& o) { return o.spec->name == cloud.emission->object; });
            if (cloud.emission->from == EmissionSource::Inside && !named->isClosed)
                throw OptionError(key, "\"" + cloud.emission->object + "\" is not closed: nothing is inside it");
            mesh = &named->mesh;
            mEmitterObjects.back() = int(named - mObjects.begin());
        }
        mEmitters.emplace_back(mSetup, c, uint32_t(nextId), mesh);
        nextId += mEmitters.back().idCount();
        if (nextId > std::numeric_limits<uint32_t>::max())
            throw OptionError("clouds/" + std::to_string(c) + "/emission/rate",
                              "the clouds would emit more than 2^32 particles over the frames");
    }
    if (mEmitters.empty()) return;
    // Every particle gets a life; those emitted at the start live for ever.
    mParticles.birth.assign(mParticles.size(), -std::numeric_limits<float>::infinity());
    mParticles.death.assign(mParticles.size(), std::numeric_limits<float>::infinity());
    mParticles.fade.assign(mParticles.size(), 1.0f);
}

void Simulator::emitAndExpire(double t)
{
    if (mEmitters.empty()) return;
    std::vector<uint8_t> alive(mParticles.size());
    bool anyDead = false;
    for (std::size_t p = 0; p < alive.size(); ++p) {
        alive[p] = double(mParticles.death[p]) > t;
        anyDead = anyDead || !alive[p];
    }
    if (anyDead) mParticles.keep(alive);
    for (std::size_t e = 0; e < mEmitters.size(); ++e) {
        Emitter& emitter = mEmitters[e];
        for (const Emitter::Birth& birth : emitter.birthsUpTo(t)) {
            if (mKeep && !mKeep(birth.id)) continue;
            Vec3d p = emitter.position(birth.number);
            if (const int object = mEmitterObjects[e]; object >= 0)
                p = poseAt(std::size_t(object), birth.time).worldFromObject(p);
            const CloudSettings& cloud = emitter.cloud();
            mParticles.position.emplace_back(p);
            mParticles.velocity.emplace_back(cloud.velocity);
            mParticles.rest.emplace_back(p);
            if (!mParticles.rest2.empty()) mParticles.rest2.emplace_back(p);
            mParticles.peak.push_back(float(p.y()));
            mParticles.origin.push_back(float(p.y()));
            mParticles.birth.push_back(float(birth.time));
            mParticles.death.push_back(float(birth.death));
            mParticles.fade.push_back(0.0f);
            mParticles.id.push_back(birth.id);
            mParticles.radius.push_back(float(cloud.particleRadius));
            mParticles.cloud.push_back(uint16_t(emitter.cloudIndex()));
        }
    }
    for (std::size_t p = 0; p < mParticles.size(); ++p) {
        const CloudSettings& cloud = mSetup.clouds[mParticles.cloud[p]];
        mParticles.fade[p] =
            cloud.emission ? float(lifeFade(*cloud.emission, mParticles.birth[p], mParticles.death[p], t)) : 1.0f;
    }
}

openvdb::Vec3SGrid::Ptr Simulator::staticForceGrid() const
{
    openvdb::Vec3SGrid::Ptr combined;
    for (const std::size_t i : mRepulsive) {
        const SimObject& object = mObjects[i];
        if (object.spec->isDynamic) continue;
        const Transform& pose = mStates[i].pose;
        // Forces rotate with the object; positions follow its transform.
        openvdb::Vec3SGrid::Ptr world = object.field->sampledForce()->deepCopy();
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

} // namespace vfield
