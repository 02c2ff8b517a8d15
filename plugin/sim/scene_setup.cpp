#include <vfield/sim/scene_setup.h>

#include <vfield/core/field_visitors.h>

#include <set>

#include <algorithm>
#include <cmath>

namespace vfield {

Vec3d UniformFieldSettings::accelerationAt(const Vec3d& p, double frame) const
{
    const Vec3d acceleration = valueAtFrame(animation, "acceleration", this->acceleration, frame);
    if (!box) return acceleration;
    const BBoxd region = valueAtFrame(animation, "box", *box, frame);
    // Distance from the box (0 inside); the field fades linearly over softEdge.
    double outsideSqr = 0.0;
    for (int axis = 0; axis < 3; ++axis) {
        const double d = std::max({region.min()[axis] - p[axis], 0.0, p[axis] - region.max()[axis]});
        outsideSqr += d * d;
    }
    if (outsideSqr == 0.0) return acceleration;
    if (softEdge <= 0.0) return Vec3d(0.0);
    const double outside = std::sqrt(outsideSqr);
    return outside >= softEdge ? Vec3d(0.0) : acceleration * (1.0 - outside / softEdge);
}

void ObjectSettings::validate() const { checkFields(*this); }

void CloudSettings::validate() const { checkFields(*this); }

void CloudEmissionSettings::validate() const
{
    checkFields(*this);
    require(end >= start, "end", "\"end\" comes before \"start\"");
    require(lifetime > 0.0 || lifetimeSpread == 0.0, "lifetimeSpread", "a spread needs a lifetime");
    require(lifetime == 0.0 || lifetimeSpread < lifetime, "lifetimeSpread", "the spread must be less than the lifetime");
}

void UniformFieldSettings::validate() const
{
    checkFields(*this);
    require(softEdge == 0.0 || box.has_value(), "softEdge", "\"softEdge\" needs a \"box\"");
}

bool UniformFieldSettings::acts(const std::string& name) const
{
    return affects.empty() || std::find(affects.begin(), affects.end(), name) != affects.end();
}

void SolverSettings::validate() const
{
    checkFields(*this);
    if (restPeriod != 0) {
        requireInteger("restPeriod", restPeriod, 2, SimulationSettings::kMaxFrame - 1);
        require(restPeriod % 2 == 0, "restPeriod",
                "restPeriod must be an even number of frames (or 0), not " + std::to_string(restPeriod));
    }
}

void SimulationSettings::validate() const
{
    checkFields(*this);
    require(lastFrame >= firstFrame, "frames", "\"end\" comes before \"start\"");
    std::set<std::string> names;
    for (std::size_t i = 0; i < objects.size(); ++i) {
        const std::string key = "objects/" + std::to_string(i);
        require(names.insert(objects[i].name).second, key, "another object is already named \"" + objects[i].name + "\"");
        // A potential flow deflects the clouds' wind; nothing in it would push an aircraft.
        if (objects[i].repulsion && objects[i].repulsion->method == RepulsionMethod::PotentialFlow) {
            require(!objects[i].isDynamic, key + "/repulsion/method", "potentialFlow applies to static objects only");
            const auto dynamic =
                std::find_if(objects.begin(), objects.end(), [](const ObjectSettings& o) { return o.isDynamic; });
            require(dynamic == objects.end(), key + "/repulsion/method",
                    "potentialFlow acts on clouds only, and dynamic object \"" +
                        (dynamic == objects.end() ? std::string() : dynamic->name) + "\" would pass through it");
        }
    }
    require(clouds.size() <= 65535, "clouds", "at most 65535 clouds");
    int64_t particles = 0;
    for (std::size_t i = 0; i < clouds.size(); ++i) {
        const std::string key = "clouds/" + std::to_string(i);
        const bool flows = std::any_of(objects.begin(), objects.end(), [](const ObjectSettings& o) {
            return o.repulsion && o.repulsion->method == RepulsionMethod::PotentialFlow;
        });
        require(!flows || clouds[i].drag > 0.0, key + "/drag",
                "a potential flow carries particles at acceleration / drag: needs a drag above 0");
        if (const std::optional<CloudEmissionSettings>& emission = clouds[i].emission;
            emission && (emission->from == EmissionSource::Surface || emission->from == EmissionSource::Inside))
            require(
                std::any_of(objects.begin(), objects.end(), [&](const ObjectSettings& o) { return o.name == emission->object; }),
                key + "/emission/object", "no object is named \"" + emission->object + "\"");
        particles += clouds[i].count;
        require(particles <= kMaxParticles, key,
                "the clouds ask for more than " + std::to_string(kMaxParticles) + " particles in all");
    }
    const auto requireMoving = [&](const std::string& key, const std::vector<std::string>& affects) {
        for (std::size_t n = 0; n < affects.size(); ++n) {
            const std::string& name = affects[n];
            const bool movingObject = std::any_of(objects.begin(), objects.end(),
                                                  [&](const ObjectSettings& o) { return o.name == name && o.isDynamic; });
            const bool cloud = std::any_of(clouds.begin(), clouds.end(), [&](const CloudSettings& c) { return c.name == name; });
            require(movingObject || cloud, key + "/affects/" + std::to_string(n),
                    "no dynamic object or cloud is named \"" + name + "\"");
        }
    };
    for (std::size_t i = 0; i < fields.size(); ++i) requireMoving("fields/" + std::to_string(i), fields[i].affects);
    for (std::size_t i = 0; i < turbulence.size(); ++i) requireMoving("turbulence/" + std::to_string(i), turbulence[i].affects);
}

} // namespace vfield
