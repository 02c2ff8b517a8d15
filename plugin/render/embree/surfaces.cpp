#include <vfield/render/embree/surfaces.h>

#include <vfield/core/error.h>

#include <embree3/rtcore.h>

#include <cmath>
#include <limits>
#include <map>
#include <string>

namespace vfield {

namespace {

/// One Embree scene holding one mesh, with the normals to shade it.
struct MeshBvh {
    RTCScene scene = nullptr;
    std::vector<Vec3f> normals;        ///< per point, in the mesh's own space
    const unsigned* indices = nullptr; ///< the triangles' corners, three a triangle (Embree's buffer)
};

void checkDevice(RTCDevice device, const char* what)
{
    const RTCError error = rtcGetDeviceError(device);
    if (error != RTC_ERROR_NONE)
        throw Error(std::string("Embree failed to ") + what + " (error " + std::to_string(int(error)) + ")");
}

MeshBvh buildBvh(RTCDevice device, const TriangleMesh& mesh, RTCBuildQuality quality)
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

/// Embree's 3x4 column-major matrix of a transform.
void toEmbree(const Transform& t, float out[12])
{
    const Mat4d m = t.matrix(); // row vectors: rows are the images of the axes
    for (int column = 0; column < 4; ++column)
        for (int row = 0; row < 3; ++row) out[3 * column + row] = float(m(column, row));
}

} // namespace

struct SurfaceScene::Impl {
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
        Transform pose;
    };
    std::vector<Dynamic> dynamics; ///< instance id = index + 1 (0 is the static one)
    RTCGeometry staticInstance = nullptr;

    /// The scene rays are traced in: with no dynamic meshes, the static BVH
    /// itself, which saves traversing the instance level.
    RTCScene traced() const { return dynamics.empty() && staticBvh.scene ? staticBvh.scene : top; }

    ~Impl()
    {
        for (Dynamic& d : dynamics)
            if (d.bvh.scene) rtcReleaseScene(d.bvh.scene);
        if (staticBvh.scene) rtcReleaseScene(staticBvh.scene);
        if (top) rtcReleaseScene(top);
        if (device) rtcReleaseDevice(device);
    }
};

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
    d.bvh = buildBvh(mImpl->device, mesh, RTC_BUILD_QUALITY_HIGH);
    d.instance = rtcNewGeometry(mImpl->device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(d.instance, d.bvh.scene);
    rtcAttachGeometryByID(mImpl->top, d.instance, unsigned(mImpl->dynamics.size() + 1));
    rtcReleaseGeometry(d.instance); // the top scene holds it
    mImpl->dynamics.push_back(std::move(d));
}

void SurfaceScene::setPose(int object, const Transform& pose)
{
    for (Impl::Dynamic& d : mImpl->dynamics)
        if (d.object == object) {
            d.pose = pose;
            float xfm[12];
            toEmbree(pose, xfm);
            rtcSetGeometryTransform(d.instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
            rtcCommitGeometry(d.instance);
            return;
        }
    throw Error("no dynamic surface for object " + std::to_string(object));
}

void SurfaceScene::commit()
{
    if (!mImpl->staticBuilt) {
        mImpl->staticBuilt = true;
        if (!mImpl->staticMesh.empty()) {
            mImpl->staticBvh = buildBvh(mImpl->device, mImpl->staticMesh, RTC_BUILD_QUALITY_HIGH);
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

bool SurfaceScene::intersect(const Vec3d& origin, const Vec3d& dir, double tMin, double tMax, SurfaceHit& hit) const
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
    rh.ray.time = 0.0f;
    rh.hit.geomID = rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(mImpl->traced(), &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;

    // No instance: a hit in the static BVH traced directly.
    const unsigned instance = rh.hit.instID[0] == RTC_INVALID_GEOMETRY_ID ? 0 : rh.hit.instID[0];
    const MeshBvh& bvh = instance == 0 ? mImpl->staticBvh : mImpl->dynamics[instance - 1].bvh;
    const Transform* pose = instance == 0 ? nullptr : &mImpl->dynamics[instance - 1].pose;
    // Smooth normal from the corners' normals (object space), then into the world.
    const unsigned* index = bvh.indices + 3 * std::size_t(rh.hit.primID);
    const double u = rh.hit.u, v = rh.hit.v;
    Vec3d shading =
        Vec3d(bvh.normals[index[0]]) * (1 - u - v) + Vec3d(bvh.normals[index[1]]) * u + Vec3d(bvh.normals[index[2]]) * v;
    Vec3d geometric(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z); // object space of the instance
    if (pose) {
        shading = pose->rotateToWorld(shading);
        geometric = pose->rotateToWorld(geometric);
    }
    geometric = geometric.unitSafe();
    if (geometric.dot(dir) > 0) geometric = -geometric;
    shading = shading.unitSafe();
    if (shading.dot(geometric) < 0) shading = -shading;

    hit.distance = rh.ray.tfar;
    hit.position = origin + dir * hit.distance;
    hit.normal = shading;
    hit.geometricNormal = geometric;
    hit.object = instance == 0 ? mImpl->staticObjectOf[rh.hit.primID] : mImpl->dynamics[instance - 1].object;
    return true;
}

bool SurfaceScene::occluded(const Vec3d& origin, const Vec3d& dir, double tMin, double tMax) const
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
    ray.time = 0.0f;
    rtcOccluded1(mImpl->traced(), &context, &ray);
    return ray.tfar < 0.0f; // Embree sets tfar to -inf on a hit
}

} // namespace vfield
