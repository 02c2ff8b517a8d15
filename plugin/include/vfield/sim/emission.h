#pragma once
/// @file emission.h
/// CloudSettings (world space) -> particles: the particles a simulation
/// starts with (each cloud's shape filled uniformly, cut into lumps by billow
/// noise), and those an emitting cloud adds over time (Emitter). Every
/// particle is drawn from its own random stream (its cloud's seed mixed with
/// the scene's and its number), so the same scene gives the same particles on
/// every machine, for any thread count and any shard.

#include <vfield/core/noise.h>
#include <vfield/mesh/triangle_mesh.h>
#include <vfield/sim/particles.h>
#include <vfield/sim/scene_setup.h>

#include <openvdb/math/Transform.h>

#include <cstdint>
#include <limits>
#include <queue>
#include <vector>

namespace vfield {

/// Every cloud's particles but those of clouds that emit over time, in cloud
/// order, ids from 0; rest positions where they are emitted.
ParticleSet emitClouds(const SimulationSettings& setup);

/// The share of its density a particle born at `birth` and dying at `death`
/// (seconds; infinity: never) has at time t: rising smoothly from 0 to 1
/// over the emission's fade after its birth, falling to 0 over it before its death.
double lifeFade(const CloudEmissionSettings& emission, double birth, double death, double t);

/// The particles one cloud emits over time (CloudEmissionSettings). The
/// k-th particle is born when the rate's integral since `start` reaches
/// k + 1/2, so that the count born by any time is the integral rounded: no
/// drift, whatever the frames. A particle due while `count` particles are
/// alive (born and not yet dead: lifetimes alone decide, not where the
/// particles went, so that every shard decides alike) is not emitted.
class Emitter {
public:
    /// One particle due.
    struct Birth {
        int64_t number; ///< k: its place in the emitter's sequence
        uint32_t id;    ///< firstId + k
        double time;    ///< seconds from the first frame
        double death;   ///< seconds from the first frame; infinity: never
    };

    /// The cloud `cloud` of setup, which emits; its particles take the ids
    /// from firstId on. mesh: the object's, in object space, for a surface or
    /// inside source (closed for inside); null otherwise.
    Emitter(const SimulationSettings& setup, std::size_t cloud, uint32_t firstId, const TriangleMesh* mesh);

    /// How many particles fall due by time t (seconds from the first frame),
    /// those the cap holds back included.
    int64_t dueBy(double t) const;
    /// The particles due after those of the last call, up to time t, in
    /// order, those the cap holds back left out.
    std::vector<Birth> birthsUpTo(double t);
    /// Where particle k is born: in world space, or, for a surface or inside
    /// source, in the object's space (to be placed as it stands at its birth).
    Vec3d position(int64_t k) const;
    const CloudSettings& cloud() const { return mCloud; }
    std::size_t cloudIndex() const { return mIndex; }
    /// The ids this emitter may hand out over the scene's frames.
    uint32_t idCount() const;

    /// Forgets every birth: the next call starts from the first particle.
    void restart();

private:
    /// The seed of particle k's stream for one purpose.
    uint64_t streamSeed(int64_t k, uint64_t purpose) const;
    double integralUpTo(double frame) const;
    /// The frame at which the rate's integral since start reaches target.
    double frameOfIntegral(double target) const;

    const SimulationSettings& mSetup;
    const CloudSettings& mCloud;
    const CloudEmissionSettings& mEmission;
    std::size_t mIndex;
    uint32_t mFirstId;
    const TriangleMesh* mMesh;
    GradientNoise mPuffs;
    /// Surface: cumulative triangle areas; inside: the mesh's bounds; volume:
    /// the boxes of voxels and tiles above threshold (index space, with the
    /// grid's transform) and their cumulative densities.
    std::vector<double> mCumulative;
    std::vector<BBoxd> mBoxes;
    openvdb::math::Transform::Ptr mVolumeTransform;
    BBoxd mMeshBounds;
    int64_t mNext = 0; ///< the next particle's number

    /// The deaths of the particles emitted and alive, soonest first.
    std::priority_queue<double, std::vector<double>, std::greater<double>> mDeaths;
};

} // namespace vfield
