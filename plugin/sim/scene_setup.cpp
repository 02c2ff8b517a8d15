#include <vfield/sim/scene_setup.h>

#include <vfield/core/error.h>

#include <algorithm>
#include <cmath>

namespace vfield {

Vec3d UniformFieldSpec::accelerationAt(const Vec3d& p) const
{
    if (!box) return acceleration;
    // Distance from the box (0 inside); the field fades linearly over softEdge.
    double outsideSqr = 0.0;
    for (int axis = 0; axis < 3; ++axis) {
        const double d = std::max({box->min()[axis] - p[axis], 0.0, p[axis] - box->max()[axis]});
        outsideSqr += d * d;
    }
    if (outsideSqr == 0.0) return acceleration;
    if (softEdge <= 0.0) return Vec3d(0.0);
    const double outside = std::sqrt(outsideSqr);
    return outside >= softEdge ? Vec3d(0.0) : acceleration * (1.0 - outside / softEdge);
}

BBoxd boxFromJson(const JsonValue& json)
{
    JsonObject o(json);
    const Vec3d min = o.at("min").asVec3(), max = o.at("max").asVec3();
    for (int axis = 0; axis < 3; ++axis)
        if (!(max[axis] > min[axis])) json.fail("max must exceed min on every axis");
    o.finish();
    return BBoxd(min, max);
}

Transform transformFromJson(const JsonValue& json)
{
    JsonObject o(json);
    Transform t;
    t.translation = o.vec3("translate", t.translation);
    t.rotation = Transform::rotationFromDegrees(o.vec3("rotateDegrees", Vec3d(0.0)));
    t.scale = o.number("scale", 1.0, 1e-9, 1e9);
    o.finish();
    return t;
}

ObjectSpec objectSpecFromJson(const JsonValue& json, const std::string& baseDir)
{
    JsonObject o(json);
    ObjectSpec spec;
    spec.name = o.at("name").asString();
    spec.mesh = meshSourceFromJson(o.at("mesh"), baseDir);
    if (const auto t = o.find("transform")) spec.transform = transformFromJson(*t);
    const std::string motion = o.choice("motion", "static", {"static", "dynamic"});
    spec.isDynamic = motion == "dynamic";
    if (const auto repulsion = o.find("repulsion")) {
        if (repulsion->isBool()) {
            if (repulsion->asBool()) spec.repulsion = OctreeFieldOptions{};
            else spec.repulsion.reset();
        } else {
            spec.repulsion = octreeFieldOptionsFromJson(*repulsion);
        }
    }
    if (spec.isDynamic) {
        spec.mass = o.number("mass", spec.mass, 1e-9, 1e12);
        spec.drag = o.number("drag", spec.drag, 0, 1e6);
        spec.velocity = o.vec3("velocity", spec.velocity);
        spec.bank = o.boolean("bank", spec.bank);
    } else {
        for (const char* key : {"mass", "drag", "velocity", "bank"})
            if (o.has(key)) o.at(key).fail(std::string("\"") + key + "\" applies to dynamic objects only");
    }
    o.finish();
    return spec;
}

CloudSpec cloudSpecFromJson(const JsonValue& json)
{
    JsonObject o(json);
    CloudSpec c;
    c.name = o.string("name", "cloud");
    c.count = o.integer("count", c.count, 1, kMaxParticles);
    const std::string shape = o.choice("shape", "sphere", {"sphere", "ellipsoid", "box"});
    c.center = o.vec3("center", c.center);
    if (shape == "sphere") {
        c.shape = CloudSpec::Shape::Sphere;
        c.radii = Vec3d(o.number("radius", 10.0, 1e-9, 1e9));
    } else {
        c.shape = shape == "box" ? CloudSpec::Shape::Box : CloudSpec::Shape::Ellipsoid;
        const JsonValue extent = o.at(shape == "box" ? "halfSize" : "radii");
        c.radii = extent.asVec3();
        if (!(c.radii[0] > 0 && c.radii[1] > 0 && c.radii[2] > 0)) extent.fail("expected three positive numbers");
    }
    c.particleRadius = o.number("particleRadius", c.particleRadius, 1e-9, 1e9);
    c.mass = o.number("mass", c.mass, 1e-9, 1e12);
    c.drag = o.number("drag", c.drag, 0, 1e6);
    c.velocity = o.vec3("velocity", c.velocity);
    c.seed = uint64_t(o.integer("seed", int64_t(c.seed), 0, INT64_MAX));
    o.finish();
    return c;
}

UniformFieldSpec uniformFieldSpecFromJson(const JsonValue& json)
{
    JsonObject o(json);
    UniformFieldSpec f;
    f.name = o.string("name", "field");
    f.acceleration = o.at("acceleration").asVec3();
    if (const auto box = o.find("box")) f.box = boxFromJson(*box);
    f.softEdge = o.number("softEdge", 0.0, 0.0, 1e12);
    if (f.softEdge > 0 && !f.box) o.at("softEdge").fail("\"softEdge\" needs a \"box\"");
    o.finish();
    return f;
}

SimulationOptions simulationOptionsFromJson(const JsonValue& json)
{
    JsonObject o(json);
    SimulationOptions s;
    s.sampling = o.choice("sampling", "nearest", {"nearest", "trilinear"}) == "nearest" ? SimulationOptions::Sampling::Nearest
                                                                                        : SimulationOptions::Sampling::Trilinear;
    s.cfl = o.number("cfl", s.cfl, 1e-3, 1.0);
    if (const auto domain = o.find("domain")) s.domain = boxFromJson(*domain);
    o.finish();
    return s;
}

} // namespace vfield
