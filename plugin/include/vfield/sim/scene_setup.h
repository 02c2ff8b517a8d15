#pragma once
/// @file scene_setup.h
/// What the simulator animates, as typed options parsed once from the scene
/// file: objects (static or dynamic meshes with repulsive octree fields),
/// particle clouds, uniform acceleration fields (gravity, wind, driving
/// forces) and turbulence. Units: world units, seconds, mass units; y is up.

#include <vfield/core/animation.h>
#include <vfield/core/fields.h>
#include <vfield/core/transform.h>
#include <vfield/field/repulsion_field.h>
#include <vfield/mesh/mesh_source.h>
#include <vfield/sim/turbulence.h>

#include <optional>
#include <string>
#include <vector>

namespace vfield {

/// The most particles a scene may ask for in all: memory for state and splats.
constexpr int64_t kMaxParticles = 50'000'000;

struct ObjectSettings {
    std::string name;
    MeshSettings mesh;
    Transform transform;
    bool isDynamic = false; ///< the key "motion"
    double mass = 1.0;
    double drag = 0.0;
    Vec3d velocity{0.0};
    /// The mesh's nose is +x and its up +y in object space; its heading and
    /// pitch follow the velocity.
    bool bank = false;
    double maxRollRate = 90.0;
    double maxPitchRate = 60.0;
    std::optional<RepulsionSettings> repulsion = RepulsionSettings{};
    Vec3d color{0.62, 0.62, 0.66};

    /// Throws OptionError naming the first option out of range.
    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        constexpr const char* kDynamicOnly = "applies to dynamic objects only";
        visit(field("name", self.name).required().doc("unique among objects"));
        visit(field("mesh", self.mesh)
                  .required()
                  .doc("exactly one of file, terrain, heightmap, sphere, box, and optionally tessellate"));
        visit(field("color", self.color)
                  .range(0, 1)
                  .unit("linear RGB")
                  .doc("for renderers: the diffuse reflectance of a mesh that is not ground (terrain and heightmaps are shaded "
                       "as rock, grass and snow)"));
        visit(field("transform", self.transform).doc("placement of the mesh; a dynamic object's at the first frame"));
        visit(field("motion", self.isDynamic).names("static", "dynamic").doc("dynamic objects move through the fields"));
        visit(field("repulsion", self.repulsion)
                  .orBoolean()
                  .doc("the object's repulsive field (the paper's octree unless method says otherwise); false: none"));
        visit(field("mass", self.mass)
                  .onlyWhen(self.isDynamic, kDynamicOnly)
                  .range(1e-9, 1e12)
                  .doc("dynamic only: repulsive forces are divided by it"));
        visit(field("drag", self.drag)
                  .onlyWhen(self.isDynamic, kDynamicOnly)
                  .range(0, 1e6)
                  .unit("1/s")
                  .doc("dynamic only: deceleration per unit velocity"));
        visit(field("velocity", self.velocity)
                  .onlyWhen(self.isDynamic, kDynamicOnly)
                  .unit("world units/s")
                  .doc("dynamic only: initial velocity"));
        visit(field("bank", self.bank)
                  .onlyWhen(self.isDynamic, kDynamicOnly)
                  .doc("dynamic only: roll into turns, by atan(sideways acceleration / 9.81), at most 60 degrees"));
        visit(field("maxRollRate", self.maxRollRate)
                  .onlyWhen(self.isDynamic, kDynamicOnly)
                  .range(0, 1e5)
                  .unit("degrees/s")
                  .doc("dynamic only: it rolls at most this fast, per frame this / fps"));
        visit(field("maxPitchRate", self.maxPitchRate)
                  .onlyWhen(self.isDynamic, kDynamicOnly)
                  .range(0, 1e5)
                  .unit("degrees/s")
                  .doc("dynamic only: it pitches at most this fast"));
    }
};

/// Where an emitter places its particles.
enum class EmissionSource {
    Shape,   ///< the cloud's own shape (sphere, ellipsoid, box), billowed as its first particles are
    Surface, ///< an object's mesh surface, by area, where it stands at the particle's birth
    Inside,  ///< inside an object's closed mesh, uniformly
    Volume   ///< a density VDB's voxels above a threshold, in proportion to their density
};
inline constexpr EnumName<EmissionSource> kEmissionSourceNames[] = {{EmissionSource::Shape, "shape"},
                                                                    {EmissionSource::Surface, "surface"},
                                                                    {EmissionSource::Inside, "inside"},
                                                                    {EmissionSource::Volume, "volume"}};
constexpr const auto& enumNames(EmissionSource) { return kEmissionSourceNames; }

/// A cloud that keeps emitting, as Houdini's POP Source and Blender's
/// emitters do: `rate` particles a second from `start` to `end`, each living
/// `lifetime` seconds (plus or minus lifetimeSpread; 0: for ever), its
/// density fading in after its birth and out before its death over `fade`
/// seconds, so that nothing pops. The cloud's count caps the particles
/// alive at once: a particle due while the cap is reached is not emitted.
struct CloudEmissionSettings {
    double rate = 1000.0;
    double start = 1.0, end = 9999.0;
    double lifetime = 0.0, lifetimeSpread = 0.0;
    double fade = 0.5;
    EmissionSource from = EmissionSource::Shape;
    std::string object;
    std::string file;
    std::string grid = "density";
    double threshold = 0.0;
    Animation animation;

    /// Throws OptionError naming the first option out of range.
    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("rate", self.rate)
                  .animatable(self.animation)
                  .range(0, 1e9)
                  .unit("particles/s")
                  .doc("how many particles a second it emits; over a run it emits the rate's integral, to within one"));
        visit(field("start", self.start).unit("frames").doc("when it starts emitting"));
        visit(field("end", self.end).unit("frames").doc("when it stops, not before start"));
        visit(field("lifetime", self.lifetime).range(0, 1e9).unit("s").doc("how long a particle lives; 0: for ever"));
        visit(field("lifetimeSpread", self.lifetimeSpread)
                  .range(0, 1e9)
                  .unit("s")
                  .doc("each particle's lifetime is drawn uniformly within lifetime plus or minus this, less than lifetime"));
        visit(field("fade", self.fade)
                  .range(0, 1e9)
                  .unit("s")
                  .doc("a particle's density fades in over this after its birth and out over this before its death "
                       "(smoothly); 0: it appears and vanishes at once"));
        visit(field("from", self.from)
                  .doc("shape: the cloud's shape; surface: an object's mesh surface; inside: inside an object's closed "
                       "mesh; volume: a density VDB's voxels above threshold, in proportion to their density"));
        visit(field("object", self.object)
                  .onlyWhen(self.from == EmissionSource::Surface || self.from == EmissionSource::Inside,
                            "applies to \"from\": \"surface\" or \"inside\" only")
                  .required()
                  .doc("the object emitted from, as it stands at each particle's birth"));
        visit(field("file", self.file)
                  .onlyWhen(self.from == EmissionSource::Volume, "applies to \"from\": \"volume\" only")
                  .required()
                  .isPath()
                  .doc("the VDB file emitted from, in world space"));
        visit(field("grid", self.grid)
                  .onlyWhen(self.from == EmissionSource::Volume, "applies to \"from\": \"volume\" only")
                  .doc("the float grid of that file"));
        visit(field("threshold", self.threshold)
                  .onlyWhen(self.from == EmissionSource::Volume, "applies to \"from\": \"volume\" only")
                  .atLeast(0)
                  .doc("voxels of at most this density emit nothing"));
    }
};

struct CloudSettings {
    enum class Shape { Sphere, Ellipsoid, Box };
    static constexpr EnumName<Shape> kShapeNames[] = {
        {Shape::Sphere, "sphere"}, {Shape::Ellipsoid, "ellipsoid"}, {Shape::Box, "box"}};
    friend constexpr const auto& enumNames(Shape) { return kShapeNames; }
    std::string name = "cloud";
    int64_t count = 10000;
    Shape shape = Shape::Sphere;
    Vec3d center{0.0};
    Vec3d radii{10.0, 10.0, 10.0}; ///< sphere: radius (all equal); ellipsoid: semi-axes; box: half extents
    double billow = 0.0;           ///< drawn by billow noise on the emitted positions
    double billowSize = 0.0;
    double particleRadius = 0.5;
    double mass = 1.0;
    double drag = 0.5;
    Vec3d velocity{0.0};
    uint64_t seed = 1;
    std::optional<CloudEmissionSettings> emission;

    /// Throws OptionError naming the first option out of range.
    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("name", self.name).doc("what uniform fields' affects name"));
        visit(field("count", self.count).range(1, double(kMaxParticles)).doc("particles; with emission, the most alive at once"));
        visit(field("shape", self.shape).doc("sphere (radius), ellipsoid (radii) or box (halfSize)"));
        visit(field("center", self.center).unit("world units").doc("centre of the shape"));
        visit(field("radius", uniformOf(self.radii))
                  .onlyWhen(self.shape == Shape::Sphere, "applies to a sphere only")
                  .range(1e-9, 1e9)
                  .unit("world units")
                  .doc("sphere: its radius"));
        visit(field("radii", self.radii)
                  .onlyWhen(self.shape == Shape::Ellipsoid, "applies to an ellipsoid only")
                  .required()
                  .range(1e-9, 1e9)
                  .unit("world units")
                  .doc("ellipsoid: its semi-axes"));
        visit(field("halfSize", self.radii)
                  .onlyWhen(self.shape == Shape::Box, "applies to a box only")
                  .required()
                  .range(1e-9, 1e9)
                  .unit("world units")
                  .doc("box: its half extents"));
        visit(field("billow", self.billow)
                  .range(0, 0.9)
                  .doc("a cumulus outline: the shape's surface is pulled in by up to this fraction of its radii where "
                       "billow noise is high (rounded lumps, creases between); 0 fills the plain shape"));
        visit(field("billowSize", self.billowSize)
                  .range(0, 1e9)
                  .unit("world units")
                  .defaultText("a third of the smallest radius")
                  .doc("the size of the largest lumps; 0: the default"));
        visit(field("particleRadius", self.particleRadius)
                  .range(1e-9, 1e9)
                  .unit("world units")
                  .doc("the particles' pscale; the density's default voxel and kernel scale with it"));
        visit(field("mass", self.mass)
                  .range(1e-9, 1e12)
                  .doc("per particle: repulsive forces are divided by it (uniform fields are accelerations)"));
        visit(field("drag", self.drag).range(0, 1e6).unit("1/s").doc("deceleration per unit velocity"));
        visit(field("velocity", self.velocity).unit("world units/s").doc("initial velocity"));
        visit(field("seed", self.seed).doc("placement of the particles, mixed with the scene's seed"));
        visit(field("emission", self.emission)
                  .doc("emit over time instead of all at the first frame; the shape's keys still place what it emits from it"));
    }
};

/// A uniform acceleration (world units/s^2), everywhere or inside a box whose
/// influence fades to zero across a soft edge outside it.
struct UniformFieldSettings {
    std::string name = "field";
    Vec3d acceleration{0.0};
    std::optional<BBoxd> box;
    double softEdge = 0.0;
    std::vector<std::string> affects; ///< empty: everything that moves
    Animation animation;

    /// Whether it acts on the object or cloud of this name.
    bool acts(const std::string& name) const;

    /// At p at frame (fractional), keys resolved.
    Vec3d accelerationAt(const Vec3d& p, double frame) const;
    /// Whether its acceleration is the same everywhere and at every frame.
    bool isUniformAndConstant() const { return !box && animation.empty(); }
    /// Throws OptionError naming the first option out of range.
    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("name", self.name).doc("for messages"));
        visit(field("acceleration", self.acceleration)
                  .animatable(self.animation)
                  .required()
                  .unit("world units/s^2")
                  .doc("gravity, wind or a driving force: it acts alike on every mass"));
        visit(field("box", self.box).animatable(self.animation).defaultText("everywhere").doc("the field acts inside this box"));
        visit(field("softEdge", self.softEdge)
                  .range(0, 1e12)
                  .unit("world units")
                  .doc("with a box: the field fades linearly to zero over this distance outside it"));
        visit(field("affects", self.affects)
                  .defaultText("everything that moves")
                  .doc("names of the dynamic objects and clouds it acts on (each aircraft its own driving force); a name that is "
                       "neither is an error"));
    }
};

struct SolverSettings {
    using Sampling = FieldSampling;
    Sampling sampling = Sampling::Dual;
    double cfl = 0.5;
    /// Unset: the union of all fields' root cubes and the clouds' initial boxes.
    std::optional<BBoxd> domain;
    /// Blended by ParticleSet::rest2Weight: detail drawn at rest stretches
    /// with the material no more than one period's motion.
    int restPeriod = 0;
    /// The clouds' condensation (VolumeSettings) counts their descent from
    /// where the preroll leaves them.
    int preroll = 0;

    /// Throws OptionError naming the first option out of range.
    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("sampling", self.sampling)
                  .doc("how particles read the fields: dual, octree leaf forces refined level by level between leaf "
                       "centres, continuous across leaf faces and changes of level; nearest, the paper's exact leaf forces, "
                       "constant over each leaf; "
                       "trilinear, between voxel centres, smooth within the finest leaves only"));
        visit(field("cfl", self.cfl)
                  .range(1e-3, 1)
                  .doc("per substep nothing moves more than cfl x the leaf size of the fields around it, relative to them"));
        visit(field("domain", self.domain)
                  .defaultText("all fields' roots and clouds")
                  .doc("particles leaving it are removed and counted"));
        visit(field("restPeriod", self.restPeriod)
                  .range(0, 9998)
                  .unit("frames")
                  .doc("dual rest: every particle's rest is reset every restPeriod frames, a second rest half a period "
                       "later, blended so that no reset shows (an even number); 0: the emitted position for good"));
        visit(field("preroll", self.preroll)
                  .range(0, 9999)
                  .unit("frames")
                  .doc("the clouds move this many frames before the first, the objects held at their first poses, so "
                       "that the flow shapes them before they are seen; they rest where it leaves them"));
    }
};

struct SimulationSettings {
    static constexpr int kMaxFrame = 9999; ///< frame numbers have four digits in file names

    int firstFrame = 1;
    int lastFrame = 120;
    double fps = 24.0;
    uint64_t seed = 1;
    std::vector<ObjectSettings> objects;
    std::vector<CloudSettings> clouds;
    std::vector<UniformFieldSettings> fields;
    std::vector<TurbulenceSettings> turbulence;
    SolverSettings solver;

    double frameTime(int frame) const { return (frame - firstFrame) / fps; }
    /// The frame (fractional) at a time from the first frame: where keys are read.
    double frameAt(double time) const { return firstFrame + time * fps; }
    /// Checks every part (keys as in a scene file: "frames/end",
    /// "objects/1/mass", "clouds/0/count", ...), unique object names and the
    /// particles in all. Throws OptionError.
    void validate() const;

    /// A scene file's keys that shape its simulation.
    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(group("frames", "frame numbers and their rate; frame f is at time (f - start) / fps", [&self](auto& frames) {
            frames(field("start", self.firstFrame).range(0, kMaxFrame).doc("first frame"));
            frames(field("end", self.lastFrame).range(0, kMaxFrame).doc("last frame, not before start"));
            frames(field("fps", self.fps).range(1e-3, 1e4).doc("frames per second"));
        }));
        visit(field("seed", self.seed).doc("mixed into every cloud's placement"));
        visit(field("objects", self.objects).required().doc("meshes, static or dynamic, with repulsive fields"));
        visit(field("clouds", self.clouds).doc("particle clouds"));
        visit(field("fields", self.fields).doc("uniform acceleration fields: gravity, wind, driving forces"));
        visit(field("turbulence", self.turbulence).doc("curl-noise swirls at several sizes that stir clouds, divergence-free"));
        visit(field("simulation", self.solver).doc("sampling, step size, domain, rest, preroll"));
    }
};

} // namespace vfield
