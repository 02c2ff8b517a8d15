#pragma once
/// @file surfaces.h
/// Scene meshes -> Embree: every static mesh in one BVH (world space, built
/// once), each dynamic mesh in its own BVH placed per frame as an instance.
/// Answers closest hits (with a smooth shading normal) and shadow queries.
///
/// A dynamic mesh may move over a shutter (setMotion): Embree's motion blur
/// places it at each ray's time, 0 at the shutter's open and 1 at its close,
/// between the two poses by interpolate() (its quaternion decomposition).

#include <vfield/core/transform.h>
#include <vfield/mesh/triangle_mesh.h>

#include <memory>
#include <vector>

namespace vfield {

struct SurfaceHit {
    double distance = 0.0; ///< along the (unit) ray
    Vec3d position;        ///< world space
    Vec3d objectPosition;  ///< in a dynamic object's own space (its pose at the ray's time undone); a static's: world space
    Vec3d normal;          ///< world space, unit, facing the ray
    Vec3d geometricNormal; ///< world space, unit, facing the ray
    int object = -1;       ///< index given to addStatic / addDynamic
};

class SurfaceScene {
public:
    SurfaceScene();
    ~SurfaceScene();
    SurfaceScene(const SurfaceScene&) = delete;
    SurfaceScene& operator=(const SurfaceScene&) = delete;

    /// A static mesh placed once (world = transform x mesh).
    void addStatic(int object, const TriangleMesh& mesh, const Transform& transform);
    /// A dynamic mesh, in object space; place it with setPose or setMotion before commit().
    void addDynamic(int object, const TriangleMesh& mesh);
    void setPose(int object, const Transform& pose);
    /// The object moves from `open` at time 0 to `close` at time 1.
    void setMotion(int object, const Transform& open, const Transform& close);
    /// Builds what changed: the static BVH the first time, the instances always.
    void commit();

    /// The closest hit along origin + t dir (dir unit), t in (tMin, tMax), at
    /// the shutter's time (in [0, 1]).
    bool intersect(const Vec3d& origin, const Vec3d& dir, double tMin, double tMax, SurfaceHit& hit, float time = 0.0f) const;
    /// Is anything in the way within (tMin, tMax)?
    bool occluded(const Vec3d& origin, const Vec3d& dir, double tMin, double tMax, float time = 0.0f) const;

    /// Rays traced together, as one of Embree's packets. Camera rays through
    /// neighbouring pixels, and their shadow rays towards the sun, are
    /// coherent: a packet traces them faster than as many rays one at a time.
    static constexpr int kPacket = 8;
    /// found[i] = intersect(origins[i], dirs[i], tMin, tMax, hits[i], times[i])
    /// for i < count <= kPacket, the same hits, traced as one packet (times
    /// null: all at 0).
    void intersect(const Vec3d* origins, const Vec3d* dirs, int count, double tMin, double tMax, SurfaceHit* hits, bool* found,
                   const float* times = nullptr) const;
    /// blocked[i] = occluded(origins[i], dirs[i], tMin, tMax, times[i]) for
    /// the rays with active[i], false for the others; i < count <= kPacket.
    void occluded(const Vec3d* origins, const Vec3d* dirs, const bool* active, int count, double tMin, double tMax, bool* blocked,
                  const float* times = nullptr) const;

    /// World-space box of all static geometry (empty when there is none).
    const BBoxd& staticBounds() const { return mStaticBounds; }

private:
    struct Impl;
    std::unique_ptr<Impl> mImpl;
    BBoxd mStaticBounds;
};

} // namespace vfield
