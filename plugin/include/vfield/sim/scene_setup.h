#pragma once
/// @file scene_setup.h
/// What the simulator animates, as typed options parsed once from the scene
/// file: objects (static or dynamic meshes with repulsive octree fields),
/// particle clouds, and uniform acceleration fields (gravity, wind, driving
/// forces). Units: world units, seconds, mass units; y is up.

#include <vfield/core/json.h>
#include <vfield/core/transform.h>
#include <vfield/field/repulsion_field.h>
#include <vfield/mesh/mesh_source.h>

#include <optional>
#include <string>
#include <vector>

namespace vfield {

/// The most particles a scene may ask for in all: memory for state and splats.
constexpr int64_t kMaxParticles = 50'000'000;

struct ObjectSpec {
    std::string name;
    MeshSource mesh;
    Transform transform;    ///< placement of the mesh (for dynamic objects: at the first frame)
    bool isDynamic = false; ///< moves through the fields (the airplane); else fixed
    double mass = 1.0;      ///< dynamic only (1e-9..1e12)
    double drag = 0.0;      ///< dynamic only: deceleration per unit velocity, 1/s (0..1e6)
    Vec3d velocity{0.0};    ///< dynamic only: initial velocity, world units/s
    /// Dynamic only: the mesh's nose is +x and its up +y in object space; its
    /// heading and pitch follow the velocity, and with bank it rolls into turns.
    bool bank = false;
    double maxRollRate = 90.0;  ///< dynamic only: degrees/s (0..1e5); per frame at most this / fps
    double maxPitchRate = 60.0; ///< dynamic only: degrees/s (0..1e5)
    std::optional<RepulsionOptions> repulsion = RepulsionOptions{}; ///< none: no field around it
    /// For renderers: the diffuse reflectance of a mesh that is not ground
    /// (terrain and heightmaps are shaded as such), linear RGB (0..1).
    Vec3d color{0.62, 0.62, 0.66};

    /// Throws OptionError naming the first option out of range.
    void validate() const;
};

struct CloudSpec {
    enum class Shape { Sphere, Ellipsoid, Box };
    std::string name;
    int64_t count = 10000; ///< particles (1..kMaxParticles)
    Shape shape = Shape::Sphere;
    Vec3d center{0.0};             ///< world units
    Vec3d radii{10.0, 10.0, 10.0}; ///< sphere: radius (all equal); ellipsoid: semi-axes; box: half extents (1e-9..1e9)
    /// How deep rounded puffs cut into the shape, a fraction of its radii
    /// (0..0.9): the outline of a cumulus, drawn by billow noise on the
    /// emitted positions; 0 fills the plain shape.
    double billow = 0.0;
    double billowSize = 0.0;     ///< world units (0..1e9): the size of the largest puffs; 0: a third of the smallest radius
    double particleRadius = 0.5; ///< world units (1e-9..1e9); the density's default voxel and kernel scale with it
    double mass = 1.0;           ///< per particle (1e-9..1e12): repulsive forces are divided by it
    double drag = 0.5;           ///< 1/s (0..1e6)
    Vec3d velocity{0.0};         ///< initial, world units/s
    uint64_t seed = 1;           ///< placement of the particles (mixed with the scene's seed)

    /// Throws OptionError naming the first option out of range.
    void validate() const;
};

/// A uniform acceleration (world units/s^2), everywhere or inside a box whose
/// influence fades to zero across a soft edge outside it.
struct UniformFieldSpec {
    std::string name;
    Vec3d acceleration{0.0};
    std::optional<BBoxd> box;
    double softEdge = 0.0; ///< world units (0..1e12): width of the linear fade outside the box; needs a box
    /// Names of the dynamic objects and clouds it acts on (each aircraft its
    /// own driving force); empty: on everything that moves.
    std::vector<std::string> affects;

    /// Whether it acts on the object or cloud of this name.
    bool acts(const std::string& name) const;

    Vec3d accelerationAt(const Vec3d& p) const;
    /// Throws OptionError naming the first option out of range.
    void validate() const;
};

struct SimulationOptions {
    enum class Sampling { Nearest, Trilinear };
    /// nearest: the paper's exact leaf forces; trilinear: smoothed across voxels.
    Sampling sampling = Sampling::Nearest;
    /// Nothing moves more than cfl x (the finest leaf size of any field) in one substep (1e-3..1).
    double cfl = 0.5;
    /// Particles leaving this box are removed (and counted). Unset: the union of
    /// all fields' root cubes and the clouds' initial boxes.
    std::optional<BBoxd> domain;
    /// Dual rest, frames (0 or an even number, 2..9998): every particle's rest
    /// position is reset to where it stands every restPeriod frames, its
    /// second rest half a period later, and detail blends the two so that no
    /// reset shows (ParticleSet::rest2Weight): detail drawn at rest stretches
    /// with the material no more than one period's motion. 0: one rest
    /// position, where the particle was emitted, never reset.
    int restPeriod = 0;

    /// Throws OptionError naming the first option out of range.
    void validate() const;
};

struct SimulationSetup {
    static constexpr int kMaxFrame = 9999; ///< frame numbers have four digits in file names

    int firstFrame = 1;  ///< frame numbers of the sequence (0..kMaxFrame)
    int lastFrame = 120; ///< (firstFrame..kMaxFrame)
    double fps = 24.0;   ///< frames per second (1e-3..1e4); frame f is at time (f - firstFrame) / fps
    uint64_t seed = 1;
    std::vector<ObjectSpec> objects;
    std::vector<CloudSpec> clouds;
    std::vector<UniformFieldSpec> fields;
    SimulationOptions options;

    double frameTime(int frame) const { return (frame - firstFrame) / fps; }
    /// Checks every part (keys as in a scene file: "frames/end",
    /// "objects/1/mass", "clouds/0/count", ...), unique object names and the
    /// particles in all. Throws OptionError.
    void validate() const;
};

/// Parsers for the scene file's sections (see scenes/README.md). Relative
/// paths resolve against baseDir. Each checks its struct (validate()) and
/// reports a failure at its JSON path, before anything is allocated.
ObjectSpec objectSpecFromJson(const JsonValue& json, const std::string& baseDir);
CloudSpec cloudSpecFromJson(const JsonValue& json);
UniformFieldSpec uniformFieldSpecFromJson(const JsonValue& json);
SimulationOptions simulationOptionsFromJson(const JsonValue& json);
Transform transformFromJson(const JsonValue& json);
BBoxd boxFromJson(const JsonValue& json);

} // namespace vfield
