#pragma once
/// @file scene_setup.h
/// What the simulator animates, as typed options parsed once from the scene
/// file: objects (static or dynamic meshes with repulsive octree fields),
/// particle clouds, and uniform acceleration fields (gravity, wind, driving
/// forces). Units: world units, seconds, mass units; y is up.

#include <vfield/core/json.h>
#include <vfield/core/transform.h>
#include <vfield/field/octree_field.h>
#include <vfield/mesh/mesh_source.h>

#include <optional>
#include <string>
#include <vector>

namespace vfield {

struct ObjectSpec {
    std::string name;
    MeshSource mesh;
    Transform transform;    ///< placement of the mesh (for dynamic objects: at the first frame)
    bool isDynamic = false; ///< moves through the fields (the airplane); else fixed
    double mass = 1.0;      ///< dynamic only (> 0)
    double drag = 0.0;      ///< dynamic only: deceleration per unit velocity, 1/s (>= 0)
    Vec3d velocity{0.0};    ///< dynamic only: initial velocity, world units/s
    /// Dynamic only: the mesh's nose is +x and its up +y in object space; its
    /// heading and pitch follow the velocity, and with bank it rolls into turns.
    bool bank = false;
    std::optional<OctreeFieldOptions> repulsion = OctreeFieldOptions{}; ///< none: no field around it
};

struct CloudSpec {
    enum class Shape { Sphere, Ellipsoid, Box };
    std::string name;
    int64_t count = 10000; ///< particles (>= 1)
    Shape shape = Shape::Sphere;
    Vec3d center{0.0};             ///< world units
    Vec3d radii{10.0, 10.0, 10.0}; ///< sphere: radius (all equal); ellipsoid: semi-axes; box: half extents
    double particleRadius = 0.5;   ///< world units; the density kernel's default radius scales with it
    double mass = 1.0;             ///< per particle (> 0): repulsive forces are divided by it
    double drag = 0.5;             ///< 1/s
    Vec3d velocity{0.0};           ///< initial, world units/s
    uint64_t seed = 1;             ///< placement of the particles (mixed with the scene's seed)
};

/// A uniform acceleration (world units/s^2), everywhere or inside a box whose
/// influence fades to zero across a soft edge outside it.
struct UniformFieldSpec {
    std::string name;
    Vec3d acceleration{0.0};
    std::optional<BBoxd> box;
    double softEdge = 0.0; ///< world units (>= 0): width of the linear fade outside the box

    Vec3d accelerationAt(const Vec3d& p) const;
};

struct SimulationOptions {
    enum class Sampling { Nearest, Trilinear };
    /// nearest: the paper's exact leaf forces; trilinear: smoothed across voxels.
    Sampling sampling = Sampling::Nearest;
    /// Nothing moves more than cfl x (the finest leaf size of any field) in one substep.
    double cfl = 0.5;
    /// Particles leaving this box are removed (and counted). Unset: the union of
    /// all fields' root cubes and the clouds' initial boxes.
    std::optional<BBoxd> domain;
};

struct SimulationSetup {
    int firstFrame = 1; ///< frame numbers of the sequence
    int lastFrame = 120;
    double fps = 24.0; ///< frames per second; frame f is at time (f - firstFrame) / fps
    uint64_t seed = 1;
    std::vector<ObjectSpec> objects;
    std::vector<CloudSpec> clouds;
    std::vector<UniformFieldSpec> fields;
    SimulationOptions options;

    double frameTime(int frame) const { return (frame - firstFrame) / fps; }
};

/// Parsers for the scene file's sections (see scenes/README.md). Relative
/// paths resolve against baseDir. Limits on sizes are checked here, before
/// anything is allocated.
ObjectSpec objectSpecFromJson(const JsonValue& json, const std::string& baseDir);
CloudSpec cloudSpecFromJson(const JsonValue& json);
UniformFieldSpec uniformFieldSpecFromJson(const JsonValue& json);
SimulationOptions simulationOptionsFromJson(const JsonValue& json);
Transform transformFromJson(const JsonValue& json);
BBoxd boxFromJson(const JsonValue& json);

/// The most particles a scene may ask for in all: memory for state and splats.
constexpr int64_t kMaxParticles = 50'000'000;

} // namespace vfield
