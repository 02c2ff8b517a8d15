#include <vfield/render/embree/surfaces.h>

#include <vfield/core/error.h>

#include <embree3/rtcore.h>
#include <embree3/rtcore_quaternion.h>

#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <string>

namespace vfield {

namespace {

void checkDevice(RTCDevice device, const char* what)
{
    const RTCError error = rtcGetDeviceError(device);
    if (error != RTC_ERROR_NONE)
        throw Error(std::string("Embree failed to ") + what + " (error " + std::to_string(int(error)) + ")");
}

/// Embree's 3x4 column-major matrix of a transform.
void toEmbree(const Transform& t, float out[12])
{
    const Mat4d m = t.matrix(); // row vectors: rows are the images of the axes
    for (int column = 0; column < 4; ++column)
        for (int row = 0; row < 3; ++row) out[3 * column + row] = float(m(column, row));
}

/// Scale, then rotation, then translation: the map Transform makes, in the
/// form Embree interpolates over time (slerp of the rotation).
RTCQuaternionDecomposition toEmbreeDecomposition(const Transform& t)
{
    RTCQuaternionDecomposition d;
    rtcInitQuaternionDecomposition(&d);
    const float s = float(t.scale);
    rtcQuaternionDecompositionSetScale(&d, s, s, s);
    const Quatd& q = t.rotation;
    rtcQuaternionDecompositionSetQuaternion(&d, float(q.w()), float(q.x()), float(q.y()), float(q.z()));
    rtcQuaternionDecompositionSetTranslation(&d, float(t.translation[0]), float(t.translation[1]), float(t.translation[2]));
    return d;
}

} // namespace

struct SurfaceScene::Impl {
    /// One Embree scene holding one mesh, with the normals to shade it.
    struct MeshBvh {
        RTCScene scene = nullptr;
        std::vector<Vec3f> normals;        ///< per point, in the mesh's own space
        const unsigned* indices = nullptr; ///< the triangles' corners, three a triangle (Embree's buffer)
    };
    static MeshBvh buildBvh(RTCDevice device, const TriangleMesh& mesh, RTCBuildQuality quality);

    RTCDevice device = nullptr;
    RTCScene top = nullptr;          ///< instances of the static BVH and of each dynamic mesh
    TriangleMesh staticMesh;         ///< world space, all static meshes
    std::vector<int> staticObjectOf; ///< per static triangle: its object
    MeshBvh staticBvh;
    bool staticBuilt = false;
    struct Dynamic {
        int object;
        MeshBvh bvh;
        RTCGeometry instance = nullptr;
        Transform pose, closingPose; ///< at times 0 and 1 (the same unless it moves)
        bool moves = false;
        Transform poseAt(float time) const { return moves ? interpolate(pose, closingPose, time) : pose; }
    };
    std::vector<Dynamic> dynamics; ///< instance id = index + 1 (0 is the static one)
    RTCGeometry staticInstance = nullptr;

    /// The scene rays are traced in: with no dynamic meshes, the static BVH
    /// itself, which saves traversing the instance level.
    RTCScene traced() const { return dynamics.empty() && staticBvh.scene ? staticBvh.scene : top; }

    Dynamic& dynamic(int object)
    {
        for (Dynamic& d : dynamics)
            if (d.object == object) return d;
        throw Error("no dynamic surface for object " + std::to_string(object));
    }

    /// What Embree found along origin + t dir (dir unit), as a SurfaceHit:
    /// the smooth normal from the corners' normals, both normals in world
    /// space and facing the ray. instance is RTC_INVALID_GEOMETRY_ID for a hit
    /// in the static BVH traced directly; ng the geometric normal in the
    /// instance's object space.
    void fill(const Vec3d& origin, const Vec3d& dir, float distance, float u, float v, unsigned primitive, unsigned instance,
              const Vec3d& ng, float time, SurfaceHit& hit) const
    {
        const unsigned index = instance == RTC_INVALID_GEOMETRY_ID ? 0 : instance;
        const MeshBvh& bvh = index == 0 ? staticBvh : dynamics[index - 1].bvh;
        Transform moving;
        const Transform* pose = index == 0 ? nullptr : &(moving = dynamics[index - 1].poseAt(time));
        const unsigned* corner = bvh.indices + 3 * std::size_t(primitive);
        const double du = u, dv = v;
        Vec3d shading = Vec3d(bvh.normals[corner[0]]) * (1 - du - dv) + Vec3d(bvh.normals[corner[1]]) * du +
                        Vec3d(bvh.normals[corner[2]]) * dv;
        Vec3d geometric = ng;
        if (pose) {
            shading = pose->rotateToWorld(shading);
            geometric = pose->rotateToWorld(geometric);
        }
        geometric = geometric.unitSafe();
        if (geometric.dot(dir) > 0) geometric = -geometric;
        shading = shading.unitSafe();
        if (shading.dot(geometric) < 0) shading = -shading;

        hit.distance = distance;
        hit.position = origin + dir * hit.distance;
        hit.objectPosition = pose ? pose->objectFromWorld(hit.position) : hit.position;
        hit.normal = shading;
        hit.geometricNormal = geometric;
        hit.object = index == 0 ? staticObjectOf[primitive] : dynamics[index - 1].object;
    }

    ~Impl()
    {
        for (Dynamic& d : dynamics)
            if (d.bvh.scene) rtcReleaseScene(d.bvh.scene);
        if (staticBvh.scene) rtcReleaseScene(staticBvh.scene);
        if (top) rtcReleaseScene(top);
        if (device) rtcReleaseDevice(device);
    }
};

SurfaceScene::Impl::MeshBvh SurfaceScene::Impl::buildBvh(RTCDevice device, const TriangleMesh& mesh, RTCBuildQuality quality)
{
    MeshBvh bvh;
    bvh.normals = vertexNormals(mesh);
    bvh.scene = rtcNewScene(device);
    rtcSetSceneBuildQuality(bvh.scene, quality);
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.points.size()));
    auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(unsigned), mesh.triangleCount()));
    checkDevice(device, "allocate a mesh");
    for (std::size_t i = 0; i < mesh.points.size(); ++i)
        for (int k = 0; k < 3; ++k) vertices[3 * i + k] = mesh.points[i][k];
    for (std::size_t t = 0; t < mesh.triangleCount(); ++t)
        for (int k = 0; k < 3; ++k) indices[3 * t + k] = mesh.triangles[t][k];
    bvh.indices = indices;
    rtcCommitGeometry(geometry);
    rtcAttachGeometryByID(bvh.scene, geometry, 0);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(bvh.scene);
    checkDevice(device, "build a BVH");
    return bvh;
}

SurfaceScene::SurfaceScene() : mImpl(std::make_unique<Impl>())
{
    mImpl->device = rtcNewDevice(nullptr);
    if (!mImpl->device) throw Error("Embree could not create a device");
    mImpl->top = rtcNewScene(mImpl->device);
}

SurfaceScene::~SurfaceScene() = default;

void SurfaceScene::addStatic(int object, const TriangleMesh& mesh, const Transform& transform)
{
    if (mImpl->staticBuilt) throw Error("static meshes must be added before the first commit");
    TriangleMesh world = mesh;
    world.transform(transform.matrix());
    mImpl->staticMesh.append(world);
    mImpl->staticObjectOf.insert(mImpl->staticObjectOf.end(), mesh.triangleCount(), object);
    mStaticBounds.expand(world.bounds());
}

void SurfaceScene::addDynamic(int object, const TriangleMesh& mesh)
{
    Impl::Dynamic d;
    d.object = object;
    d.bvh = Impl::buildBvh(mImpl->device, mesh, RTC_BUILD_QUALITY_HIGH);
    d.instance = rtcNewGeometry(mImpl->device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(d.instance, d.bvh.scene);
    rtcAttachGeometryByID(mImpl->top, d.instance, unsigned(mImpl->dynamics.size() + 1));
    rtcReleaseGeometry(d.instance); // the top scene holds it
    mImpl->dynamics.push_back(std::move(d));
}

void SurfaceScene::setPose(int object, const Transform& pose)
{
    Impl::Dynamic& d = mImpl->dynamic(object);
    d.pose = d.closingPose = pose;
    d.moves = false;
    float xfm[12];
    toEmbree(pose, xfm);
    rtcSetGeometryTimeStepCount(d.instance, 1);
    rtcSetGeometryTransform(d.instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
    rtcCommitGeometry(d.instance);
}

void SurfaceScene::setMotion(int object, const Transform& open, const Transform& close)
{
    Impl::Dynamic& d = mImpl->dynamic(object);
    d.pose = open;
    d.closingPose = close;
    d.moves = true;
    rtcSetGeometryTimeStepCount(d.instance, 2);
    const RTCQuaternionDecomposition poses[2] = {toEmbreeDecomposition(open), toEmbreeDecomposition(close)};
    for (unsigned step = 0; step < 2; ++step) rtcSetGeometryTransformQuaternion(d.instance, step, &poses[step]);
    rtcCommitGeometry(d.instance);
}

void SurfaceScene::commit()
{
    if (!mImpl->staticBuilt) {
        mImpl->staticBuilt = true;
        if (!mImpl->staticMesh.empty()) {
            mImpl->staticBvh = Impl::buildBvh(mImpl->device, mImpl->staticMesh, RTC_BUILD_QUALITY_HIGH);
            mImpl->staticInstance = rtcNewGeometry(mImpl->device, RTC_GEOMETRY_TYPE_INSTANCE);
            rtcSetGeometryInstancedScene(mImpl->staticInstance, mImpl->staticBvh.scene);
            const float identity[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
            rtcSetGeometryTransform(mImpl->staticInstance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, identity);
            rtcCommitGeometry(mImpl->staticInstance);
            rtcAttachGeometryByID(mImpl->top, mImpl->staticInstance, 0);
            rtcReleaseGeometry(mImpl->staticInstance);
        }
    }
    rtcCommitScene(mImpl->top); // only the few instances: cheap every frame
    checkDevice(mImpl->device, "commit the scene");
}

bool SurfaceScene::intersect(const Vec3d& origin, const Vec3d& dir, double tMin, double tMax, SurfaceHit& hit, float time) const
{
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray.org_x = float(origin[0]);
    rh.ray.org_y = float(origin[1]);
    rh.ray.org_z = float(origin[2]);
    rh.ray.dir_x = float(dir[0]);
    rh.ray.dir_y = float(dir[1]);
    rh.ray.dir_z = float(dir[2]);
    rh.ray.tnear = float(tMin);
    rh.ray.tfar = float(std::min(tMax, double(std::numeric_limits<float>::max())));
    rh.ray.mask = ~0u;
    rh.ray.flags = 0;
    rh.ray.time = time;
    rh.hit.geomID = rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(mImpl->traced(), &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    mImpl->fill(origin, dir, rh.ray.tfar, rh.hit.u, rh.hit.v, rh.hit.primID, rh.hit.instID[0],
                Vec3d(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z), time, hit);
    return true;
}

namespace {

/// A packet's valid lanes: the first count, Embree's -1.
using PacketLanes = std::array<int, SurfaceScene::kPacket>;

/// A ray of a packet as the single-ray queries set it.
template<typename Ray8>
void setLane(Ray8& ray, int lane, const Vec3d& origin, const Vec3d& dir, double tMin, double tMax, float time)
{
    ray.org_x[lane] = float(origin[0]);
    ray.org_y[lane] = float(origin[1]);
    ray.org_z[lane] = float(origin[2]);
    ray.dir_x[lane] = float(dir[0]);
    ray.dir_y[lane] = float(dir[1]);
    ray.dir_z[lane] = float(dir[2]);
    ray.tnear[lane] = float(tMin);
    ray.tfar[lane] = float(std::min(tMax, double(std::numeric_limits<float>::max())));
    ray.mask[lane] = ~0u;
    ray.flags[lane] = 0;
    ray.time[lane] = time;
}

/// The context of a packet of count rays, coherent ones.
RTCIntersectContext packetContext(int count)
{
    if (count < 0 || count > SurfaceScene::kPacket)
        throw ValueError("a packet of " + std::to_string(count) + " rays (at most " + std::to_string(SurfaceScene::kPacket) +
                         ")");
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    return context;
}

} // namespace

void SurfaceScene::intersect(const Vec3d* origins, const Vec3d* dirs, int count, double tMin, double tMax, SurfaceHit* hits,
                             bool* found, const float* times) const
{
    RTCIntersectContext context = packetContext(count);
    alignas(32) PacketLanes valid{};
    alignas(32) RTCRayHit8 rh{};
    for (int lane = 0; lane < count; ++lane) {
        valid[lane] = -1;
        setLane(rh.ray, lane, origins[lane], dirs[lane], tMin, tMax, times ? times[lane] : 0.0f);
        rh.hit.geomID[lane] = rh.hit.instID[0][lane] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect8(valid.data(), mImpl->traced(), &context, &rh);
    for (int lane = 0; lane < count; ++lane) {
        found[lane] = rh.hit.geomID[lane] != RTC_INVALID_GEOMETRY_ID;
        if (found[lane])
            mImpl->fill(origins[lane], dirs[lane], rh.ray.tfar[lane], rh.hit.u[lane], rh.hit.v[lane], rh.hit.primID[lane],
                        rh.hit.instID[0][lane], Vec3d(rh.hit.Ng_x[lane], rh.hit.Ng_y[lane], rh.hit.Ng_z[lane]),
                        times ? times[lane] : 0.0f, hits[lane]);
    }
}

void SurfaceScene::occluded(const Vec3d* origins, const Vec3d* dirs, const bool* active, int count, double tMin, double tMax,
                            bool* blocked, const float* times) const
{
    RTCIntersectContext context = packetContext(count);
    alignas(32) PacketLanes valid{};
    alignas(32) RTCRay8 ray{};
    bool any = false;
    for (int lane = 0; lane < count; ++lane) {
        if (!active[lane]) continue;
        valid[lane] = -1;
        any = true;
        setLane(ray, lane, origins[lane], dirs[lane], tMin, tMax, times ? times[lane] : 0.0f);
    }
    if (any) rtcOccluded8(valid.data(), mImpl->traced(), &context, &ray);
    for (int lane = 0; lane < count; ++lane) blocked[lane] = active[lane] && ray.tfar[lane] < 0.0f; // -inf on a hit
}

bool SurfaceScene::occluded(const Vec3d& origin, const Vec3d& dir, double tMin, double tMax, float time) const
{
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray;
    ray.org_x = float(origin[0]);
    ray.org_y = float(origin[1]);
    ray.org_z = float(origin[2]);
    ray.dir_x = float(dir[0]);
    ray.dir_y = float(dir[1]);
    ray.dir_z = float(dir[2]);
    ray.tnear = float(tMin);
    ray.tfar = float(std::min(tMax, double(std::numeric_limits<float>::max())));
    ray.mask = ~0u;
    ray.flags = 0;
    ray.time = time;
    rtcOccluded1(mImpl->traced(), &context, &ray);
    return ray.tfar < 0.0f; // Embree sets tfar to -inf on a hit
}

} // namespace vfield
