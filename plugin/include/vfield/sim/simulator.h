#pragma once
/// @file simulator.h
/// SimulationSettings -> particles and dynamic objects moving frame by frame
/// through the sum of all fields (world space), collision-free because the
/// objects' repulsive octree fields push back ever harder near their surfaces
/// (or the alternatives of repulsion_field.h, for comparison).
///
/// Motion: a = sum of uniform fields and turbulence (accelerations) + sum of
/// repulsive forces / mass - drag x v, integrated by semi-implicit Euler;
/// inside a potential flow (RepulsionMethod::PotentialFlow) a particle moves
/// with the flow, at the terminal velocity a / drag. Each particle takes
/// its own substeps, sized so that it moves at most cfl x the size of the
/// field cells around it per substep, relative to every field (a dynamic
/// object sweeping over a resting particle counts): fast particles cannot
/// step through a surface between two checks, and the result does not depend
/// on the thread count. Dynamic objects (the airplane) move first each frame,
/// by the paper's hit test of their triangle centroids against every other
/// object's field; their own fields then repel particles. Orientation follows
/// velocity.
///
/// Beyond the paper, contact: a field cannot stop a particle that an object
/// overtakes faster than its force can accelerate it (a box at 50 units/s
/// through resting particles), nor, with its forces interpolated between
/// leaves (FieldSampling::Dual), one it pushes more softly near a surface
/// than the paper's field would. Where a substep's path, followed in an
/// object's frame, reaches its closed mesh's exact level set (static or
/// dynamic), the particle stays on the surface (one distance voxel out) and
/// loses its velocity into it relative to the surface's own: pushed aside
/// and carried along, never inside. StepStats counts these contacts, so
/// where the field falls short shows.

#include <vfield/core/vdb_trees.h>
#include <vfield/field/repulsion_field.h>
#include <vfield/mesh/mesh_distance.h>
#include <vfield/sim/emission.h>
#include <vfield/sim/flight.h>
#include <vfield/sim/particles.h>
#include <vfield/sim/scene_setup.h>
#include <vfield/sim/turbulence.h>

#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

namespace vfield {

/// One scene object as the simulator holds it.
struct SimObject {
    const ObjectSettings* spec = nullptr;
    TriangleMesh mesh;                           ///< object space
    std::shared_ptr<const RepulsionField> field; ///< null without repulsion
    double fieldSeconds = 0.0;                   ///< how long building and voxelizing the field took, wall clock
    std::vector<Vec3d> centroids;                ///< object space, for the hit test (dynamic objects)
    double radius = 0.0;                         ///< farthest vertex from the pivot, object units: how far rotation moves it
    MeshLoadReport loadReport;                   ///< what loading a mesh file found and repaired
    bool isClosed = false;                       ///< the mesh encloses a volume: its signed distance has an inside
    /// The mesh's signed distance, where particles make contact (closed meshes)
    /// and where objects are measured. Dynamic objects with a closed mesh:
    /// voxel 1/128 of its largest extent, out to its field's margin but at
    /// most half that extent, the whole inside; null for an open one. Static
    /// objects: voxel half the field's finest leaf, at most 1/256 of the
    /// largest extent, out to a tenth of the field's root (or of the
    /// extent), three voxels inside.
    std::shared_ptr<MeshDistance> distance;
};

/// What one frame's step did.
struct StepStats {
    uint64_t substeps = 0;        ///< particle substeps taken, summed over particles
    uint32_t maxSubsteps = 0;     ///< most substeps any particle took
    uint32_t dynamicSubsteps = 0; ///< substeps of the dynamic objects
    double maxRollChange = 0.0;   ///< the most any dynamic object rolled this frame, degrees
    uint64_t removed = 0;         ///< particles that left the domain this frame
    uint64_t contacts = 0;        ///< particle substeps that ended on an object's surface (see Simulator)
    /// Particle substeps that ended inside an object's closed mesh, by its
    /// signed distance as the object then stands: zero unless contact failed.
    uint64_t endedInside = 0;
};

class Simulator {
public:
    /// Told each step of building a simulator as it starts ("terrain: octree
    /// field of 131072 triangles"), one call at a time, from worker threads.
    using Preparing = std::function<void(const std::string& step)>;

    /// Loads or generates every mesh and builds and voxelizes the fields (in
    /// parallel), then spawns the clouds and runs their preroll
    /// (SolverSettings::preroll). Throws on bad input.
    explicit Simulator(const SimulationSettings& setup, const Preparing& preparing = {});
    // Objects point into the setup it owns: no copies (restoreState() resets one).
    Simulator(const Simulator&) = delete;
    Simulator& operator=(const Simulator&) = delete;

    const SimulationSettings& setup() const { return mSetup; }
    int frame() const { return mFrame; }
    /// Advances the state by one frame (1 / fps seconds). With dynamic
    /// objects, afterDynamicSubstep (if set) runs after each of their shared
    /// substeps, objectStates() holding the poses at its end: where an exact
    /// measure of their clearance looks (ClearanceProbe::measureObjects).
    void advanceFrame(const std::function<void()>& afterDynamicSubstep = {});

    /// A dynamic object's state at the end of a frame, from a run that moved
    /// it before (its tracks).
    using ObjectReplay = std::function<DynamicState(const SimObject& object, int frame)>;
    /// From the next frame on, the dynamic objects follow replay instead of
    /// the flight model: what a shard of a sharded simulation does, so that
    /// the objects move once for all shards. Particles read the objects'
    /// poses at frames only (between them, interpolated), so a replay of
    /// their exact poses moves particles bit for bit as the run that made them.
    void replayObjects(ObjectReplay replay) { mReplay = std::move(replay); }
    /// Keeps only the particles whose id keep accepts (a shard's share of a
    /// cloud, or none), now and as clouds emit; each moves as it would with
    /// all the others.
    void keepParticles(const std::function<bool(uint32_t id)>& keep);

    const ParticleSet& particles() const { return mParticles; }
    uint64_t removedTotal() const { return mRemovedTotal; }
    const StepStats& lastStep() const { return mLastStep; }
    const std::vector<SimObject>& objects() const { return mObjects; }
    /// Per object (same order as objects()): dynamic state, or the fixed pose of a static object.
    const std::vector<DynamicState>& objectStates() const { return mStates; }
    const BBoxd& domain() const { return mDomain; }
    /// What loading the mesh files found and repaired, a line each naming the file.
    std::vector<std::string> meshReports() const;
    /// The finest leaf size over all fields, world units: what cfl scales for
    /// the dynamic objects' shared substeps (particles use the cells around them).
    double finestCellSize() const { return mFinestCell; }

    /// The static objects' forces as particles read them (RepulsionField::sampledForce)
    /// summed into one world-space grid.
    openvdb::Vec3SGrid::Ptr staticForceGrid() const;

    /// The state after the current frame, to resume from (bit-exact).
    std::string serializeState() const;
    /// The same bytes, streamed: a cloud of millions of particles has a state
    /// of hundreds of megabytes, which a copy in memory would double.
    void writeState(std::ostream& out) const;
    /// Restores a state written by serializeState or writeState for the same setup.
    void restoreState(const std::string& bytes);

private:
    /// What bounds a particle's substep at p: the size of the smallest field
    /// cell there (world units; 1 where no field reaches), and the speed of
    /// the fastest field moving over p this frame (a dynamic object's
    /// translation plus its rotation at its root's corners; its root counts
    /// grown by its travel in the frame, since it sweeps that far).
    struct LocalBound {
        double cell = 1.0;
        double fieldSpeed = 0.0;
    };
    /// What the objects' fields do at a point, from one read of each field;
    /// without forces, the bound alone (from the fields' levels).
    struct FieldsAt {
        Vec3d acceleration{0.0}; ///< of a point of the given mass
        LocalBound bound;
        bool inFlow = false; ///< p lies in the band of a potential flow (RepulsionMethod::PotentialFlow)
        /// With forces: a world box around p over which the bound is as at
        /// p (the cells of static fields holding p, RepulsionField::levelCell);
        /// empty near a dynamic or rotated field or the edge of a field.
        BBoxd sameBound;
    };
    FieldsAt fieldsAt(const Vec3d& p, double time, double mass, RepulsionField::Accessor* accessors, bool withForces) const;
    void advanceDynamicObjects(double t0, double t1, const std::function<void()>& afterSubstep);
    /// The uniform fields and turbulence acting on one object or cloud
    /// (UniformFieldSettings::affects, TurbulenceSettings::affects).
    struct AccelerationFields {
        /// The sum of the leading uniform fields that act everywhere (no
        /// box), added in the scene's order as a substep would: the same to the bit.
        Vec3d leadingSum{0.0};
        std::vector<std::size_t> rest;       ///< the other uniform fields, indices into the setup's, in order
        std::vector<std::size_t> turbulence; ///< indices into mTurbulence
    };
    /// What the uniform fields and turbulence accelerate at p at time t (seconds).
    Vec3d fieldAcceleration(const AccelerationFields& fields, const Vec3d& p, double t) const;
    void advanceParticles(double t0, double t1);
    /// The emitting clouds' emitters, their ids after the first particles'.
    void makeEmitters();
    /// At time t (a frame's end): removes the particles whose life is over,
    /// emits those born since the last call, and sets every particle's fade.
    void emitAndExpire(double t);
    /// Dual rest (SolverSettings::restPeriod): resets the rest position due
    /// at the current frame and sets the blend between the two.
    void updateRestPositions();
    /// Contact of a particle's substep from -> x with the closed meshes
    /// (mContact). lowerBounds holds, per such object, a lower bound of the
    /// distance read where the particle starts, or -infinity: a static
    /// object's bound is carried from substep to substep (and, through
    /// mKeptBounds, from frame to frame), since reads change
    /// by at most |dx| + |dy| + |dz| over a move d, so that substeps far from its
    /// surface read nothing and decide as a read would.
    bool resolveContacts(const Vec3d& from, Vec3d& x, Vec3d& v, double t, double dt,
                         std::vector<MeshDistance::Accessor>& accessors, std::vector<double>& lowerBounds) const;
    /// Whether x lies inside an object's closed mesh as placed at time t
    /// (lowerBounds: resolveContacts's, for x).
    bool endsInside(const Vec3d& x, double t, std::vector<MeshDistance::Accessor>& accessors,
                    const std::vector<double>& lowerBounds) const;
    Transform poseAt(std::size_t object, double time) const;
    /// Per repulsive object (mRepulsive order): how fast its field moves this frame, world units / s.
    void measureFieldSpeeds(double t0, double t1);

    SimulationSettings mSetup;
    std::vector<SimObject> mObjects;
    std::vector<DynamicState> mStates, mStatesAtFrameStart;
    /// Per object: static and placed at the identity (the terrain, as a
    /// rule), so that its object space is world space and substeps skip the map.
    std::vector<uint8_t> mWorldIsObject;
    std::vector<std::size_t> mRepulsive;    ///< objects with a field
    std::vector<std::size_t> mContact;      ///< objects with a closed mesh's distance (SimObject::distance)
    std::vector<Turbulence> mTurbulence;    ///< the setup's, in its order
    std::vector<Emitter> mEmitters;         ///< the emitting clouds', in their order
    std::vector<int> mEmitterObjects;       ///< per emitter, the object it emits from, or -1
    std::function<bool(uint32_t id)> mKeep; ///< the particles this simulator keeps (keepParticles); unset: all
    /// The uniform fields and turbulence acting on each object and each cloud.
    std::vector<AccelerationFields> mObjectFields, mCloudFields;
    ParticleSet mParticles;
    BBoxd mDomain;
    double mFinestCell = 0.0;
    /// Per particle, after its last frame: its id and, per closed mesh
    /// (mContact order), resolveContacts's lower bound of its distance there
    /// (unused for dynamic objects, unknown again at every substep). A cache,
    /// not state: a particle whose id differs (sorted, removed) or a restored
    /// state reads afresh. It spares most particles' first substep of a frame
    /// its read of a static surface, and changes no decision (a bound only
    /// skips what a read would).
    struct KeptBounds {
        std::vector<uint32_t> id;
        std::vector<double> bound;
    };
    KeptBounds mKeptBounds;
    std::vector<double> mFieldSpeed; ///< per repulsive object this frame (measureFieldSpeeds)
    double mFieldFrameTime = 0.0;    ///< the frame's length, for the swept roots
    ObjectReplay mReplay;            ///< empty: the flight model moves the dynamic objects
    int mFrame = 0;
    uint64_t mRemovedTotal = 0;
    StepStats mLastStep;
};

} // namespace vfield
