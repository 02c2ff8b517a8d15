#include <vfield/sim/scene_setup.h>

#include <vfield/core/options.h>

#include <set>

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

namespace {

void requireBox(const std::string& key, const BBoxd& box)
{
    for (int axis = 0; axis < 3; ++axis) require(box.max()[axis] > box.min()[axis], key, "max must exceed min on every axis");
}

} // namespace

void ObjectSpec::validate() const
{
    validatePart("mesh", mesh);
    validatePart("transform", transform);
    requireNumber("mass", mass, 1e-9, 1e12);
    requireNumber("drag", drag, 0.0, 1e6);
    requireNumber("maxRollRate", maxRollRate, 0.0, 1e5);
    requireNumber("maxPitchRate", maxPitchRate, 0.0, 1e5);
    if (repulsion) validatePart("repulsion", *repulsion);
    for (int c = 0; c < 3; ++c) requireNumber("color/" + std::to_string(c), color[c], 0.0, 1.0);
}

void CloudSpec::validate() const
{
    requireInteger("count", count, 1, kMaxParticles);
    const char* extent = shape == Shape::Sphere ? "radius" : shape == Shape::Box ? "halfSize" : "radii";
    for (int axis = 0; axis < 3; ++axis) requireNumber(extent, radii[axis], 1e-9, 1e9);
    requireNumber("billow", billow, 0.0, 0.9);
    requireNumber("billowSize", billowSize, 0.0, 1e9);
    requireNumber("particleRadius", particleRadius, 1e-9, 1e9);
    requireNumber("mass", mass, 1e-9, 1e12);
    requireNumber("drag", drag, 0.0, 1e6);
}

void UniformFieldSpec::validate() const
{
    if (box) requireBox("box", *box);
    requireNumber("softEdge", softEdge, 0.0, 1e12);
    require(softEdge == 0.0 || box.has_value(), "softEdge", "\"softEdge\" needs a \"box\"");
}

bool UniformFieldSpec::acts(const std::string& name) const
{
    return affects.empty() || std::find(affects.begin(), affects.end(), name) != affects.end();
}

void SimulationOptions::validate() const
{
    requireNumber("cfl", cfl, 1e-3, 1.0);
    if (domain) requireBox("domain", *domain);
    if (restPeriod != 0) {
        requireInteger("restPeriod", restPeriod, 2, SimulationSetup::kMaxFrame - 1);
        require(restPeriod % 2 == 0, "restPeriod",
                "restPeriod must be an even number of frames (or 0), not " + std::to_string(restPeriod));
    }
}

void SimulationSetup::validate() const
{
    requireInteger("frames/start", firstFrame, 0, kMaxFrame);
    requireInteger("frames/end", lastFrame, 0, kMaxFrame);
    require(lastFrame >= firstFrame, "frames", "\"end\" comes before \"start\"");
    requireNumber("frames/fps", fps, 1e-3, 1e4);
    std::set<std::string> names;
    for (std::size_t i = 0; i < objects.size(); ++i) {
        const std::string key = "objects/" + std::to_string(i);
        validatePart(key, objects[i]);
        require(names.insert(objects[i].name).second, key, "another object is already named \"" + objects[i].name + "\"");
        // A potential flow deflects the clouds' wind; nothing in it would push an aircraft.
        if (objects[i].repulsion && objects[i].repulsion->method == RepulsionMethod::PotentialFlow) {
            require(!objects[i].isDynamic, key + "/repulsion/method", "potentialFlow applies to static objects only");
            const auto dynamic = std::find_if(objects.begin(), objects.end(), [](const ObjectSpec& o) { return o.isDynamic; });
            require(dynamic == objects.end(), key + "/repulsion/method",
                    "potentialFlow acts on clouds only, and dynamic object \"" +
                        (dynamic == objects.end() ? std::string() : dynamic->name) + "\" would pass through it");
        }
    }
    require(clouds.size() <= 65535, "clouds", "at most 65535 clouds");
    int64_t particles = 0;
    for (std::size_t i = 0; i < clouds.size(); ++i) {
        const std::string key = "clouds/" + std::to_string(i);
        validatePart(key, clouds[i]);
        const bool flows = std::any_of(objects.begin(), objects.end(), [](const ObjectSpec& o) {
            return o.repulsion && o.repulsion->method == RepulsionMethod::PotentialFlow;
        });
        require(!flows || clouds[i].drag > 0.0, key + "/drag",
                "a potential flow carries particles at acceleration / drag: needs a drag above 0");
        particles += clouds[i].count;
        require(particles <= kMaxParticles, key,
                "the clouds ask for more than " + std::to_string(kMaxParticles) + " particles in all");
    }
    for (std::size_t i = 0; i < fields.size(); ++i) {
        const std::string key = "fields/" + std::to_string(i);
        validatePart(key, fields[i]);
        for (std::size_t n = 0; n < fields[i].affects.size(); ++n) {
            const std::string& name = fields[i].affects[n];
            const bool movingObject =
                std::any_of(objects.begin(), objects.end(), [&](const ObjectSpec& o) { return o.name == name && o.isDynamic; });
            const bool cloud = std::any_of(clouds.begin(), clouds.end(), [&](const CloudSpec& c) { return c.name == name; });
            require(movingObject || cloud, key + "/affects/" + std::to_string(n),
                    "no dynamic object or cloud is named \"" + name + "\"");
        }
    }
    validatePart("simulation", options);
}

BBoxd boxFromJson(const JsonValue& json)
{
    JsonObject o(json);
    const Vec3d min = o.at("min").asVec3(), max = o.at("max").asVec3();
    o.finish();
    return BBoxd(min, max);
}

Transform transformFromJson(const JsonValue& json)
{
    return readOptions<Transform>(json, [&](JsonObject& o, Transform& t) {
        t.translation = o.vec3("translate", t.translation);
        t.rotation = Transform::rotationFromDegrees(o.vec3("rotateDegrees", Vec3d(0.0)));
        t.scale = o.number("scale", t.scale);
    });
}

ObjectSpec objectSpecFromJson(const JsonValue& json, const std::string& baseDir)
{
    return readOptions<ObjectSpec>(json, [&](JsonObject& o, ObjectSpec& spec) {
        spec.name = o.at("name").asString();
        spec.mesh = meshSourceFromJson(o.at("mesh"), baseDir);
        spec.color = o.vec3("color", spec.color);
        if (const auto t = o.find("transform")) spec.transform = transformFromJson(*t);
        const std::string motion = o.choice("motion", "static", {"static", "dynamic"});
        spec.isDynamic = motion == "dynamic";
        if (const auto repulsion = o.find("repulsion")) {
            if (repulsion->isBool()) {
                if (repulsion->asBool()) spec.repulsion = RepulsionOptions{};
                else spec.repulsion.reset();
            } else {
                spec.repulsion = repulsionOptionsFromJson(*repulsion);
            }
        }
        if (spec.isDynamic) {
            spec.mass = o.number("mass", spec.mass);
            spec.drag = o.number("drag", spec.drag);
            spec.velocity = o.vec3("velocity", spec.velocity);
            spec.bank = o.boolean("bank", spec.bank);
            spec.maxRollRate = o.number("maxRollRate", spec.maxRollRate);
            spec.maxPitchRate = o.number("maxPitchRate", spec.maxPitchRate);
        } else {
            for (const char* key : {"mass", "drag", "velocity", "bank", "maxRollRate", "maxPitchRate"})
                if (o.has(key)) o.at(key).fail(std::string("\"") + key + "\" applies to dynamic objects only");
        }
    });
}

CloudSpec cloudSpecFromJson(const JsonValue& json)
{
    return readOptions<CloudSpec>(json, [&](JsonObject& o, CloudSpec& c) {
        c.name = o.string("name", "cloud");
        c.count = o.integer64("count", c.count);
        const std::string shape = o.choice("shape", "sphere", {"sphere", "ellipsoid", "box"});
        c.center = o.vec3("center", c.center);
        if (shape == "sphere") {
            c.shape = CloudSpec::Shape::Sphere;
            c.radii = Vec3d(o.number("radius", c.radii[0]));
        } else {
            c.shape = shape == "box" ? CloudSpec::Shape::Box : CloudSpec::Shape::Ellipsoid;
            c.radii = o.at(shape == "box" ? "halfSize" : "radii").asVec3();
        }
        c.billow = o.number("billow", c.billow);
        c.billowSize = o.number("billowSize", c.billowSize);
        c.particleRadius = o.number("particleRadius", c.particleRadius);
        c.mass = o.number("mass", c.mass);
        c.drag = o.number("drag", c.drag);
        c.velocity = o.vec3("velocity", c.velocity);
        c.seed = o.unsignedInteger("seed", c.seed);
    });
}

UniformFieldSpec uniformFieldSpecFromJson(const JsonValue& json)
{
    return readOptions<UniformFieldSpec>(json, [&](JsonObject& o, UniformFieldSpec& f) {
        f.name = o.string("name", "field");
        f.acceleration = o.at("acceleration").asVec3();
        if (const auto box = o.find("box")) f.box = boxFromJson(*box);
        f.softEdge = o.number("softEdge", f.softEdge);
        if (const auto affects = o.find("affects"))
            for (const JsonValue& name : affects->asArray()) f.affects.push_back(name.asString());
    });
}

SimulationOptions simulationOptionsFromJson(const JsonValue& json)
{
    return readOptions<SimulationOptions>(json, [&](JsonObject& o, SimulationOptions& s) {
        s.sampling = o.choice("sampling", "nearest", {"nearest", "trilinear"}) == "nearest"
                         ? SimulationOptions::Sampling::Nearest
                         : SimulationOptions::Sampling::Trilinear;
        s.cfl = o.number("cfl", s.cfl);
        s.restPeriod = o.integer("restPeriod", s.restPeriod);
        if (const auto domain = o.find("domain")) s.domain = boxFromJson(*domain);
    });
}

} // namespace vfield
