#include <vfield/render/render_settings.h>

namespace vfield {

namespace {

Vec3d color(JsonObject& o, const std::string& key, const Vec3d& fallback)
{
    const std::optional<JsonValue> v = o.find(key);
    if (!v) return fallback;
    const Vec3d c = v->asVec3();
    if (c[0] < 0 || c[1] < 0 || c[2] < 0) v->fail("expected a colour of three numbers >= 0");
    return c;
}

} // namespace

CameraSettings cameraSettingsFromJson(const JsonValue& json)
{
    JsonObject o(json);
    CameraSettings c;
    c.position = o.vec3("position", c.position);
    c.lookAt = o.vec3("lookAt", c.lookAt);
    c.up = o.vec3("up", c.up);
    if (c.up.length() == 0) o.at("up").fail("expected a non-zero vector");
    c.fovDegrees = o.number("fovDegrees", c.fovDegrees, 1e-3, 179.0);
    if (const auto follow = o.find("follow")) {
        JsonObject f(*follow);
        c.followObject = f.at("object").asString();
        c.followOffset = f.vec3("offset", c.followOffset);
        f.finish();
    } else if ((c.position - c.lookAt).length() == 0) {
        json.fail("position and lookAt must differ");
    }
    o.finish();
    return c;
}

SunSettings sunSettingsFromJson(const JsonValue& json)
{
    JsonObject o(json);
    SunSettings s;
    s.direction = o.vec3("direction", s.direction);
    if (s.direction.length() == 0) o.at("direction").fail("expected a non-zero vector");
    s.color = color(o, "color", s.color);
    s.intensity = o.number("intensity", s.intensity, 0, 1e6);
    o.finish();
    return s;
}

SkySettings skySettingsFromJson(const JsonValue& json)
{
    JsonObject o(json);
    SkySettings s;
    s.zenithColor = color(o, "zenithColor", s.zenithColor);
    s.horizonColor = color(o, "horizonColor", s.horizonColor);
    s.intensity = o.number("intensity", s.intensity, 0, 1e6);
    o.finish();
    return s;
}

ImageSettings imageSettingsFromJson(const JsonValue& json)
{
    JsonObject o(json);
    ImageSettings s;
    if (const auto resolution = o.find("resolution")) {
        const std::vector<JsonValue> wh = resolution->asArray();
        if (wh.size() != 2) resolution->fail("expected [width, height]");
        s.width = int(wh[0].asInteger(1, 16384));
        s.height = int(wh[1].asInteger(1, 16384));
    }
    s.samplesPerPixel = int(o.integer("samplesPerPixel", s.samplesPerPixel, 1, 65536));
    s.volumeStep = o.number("volumeStep", s.volumeStep, 1e-6, 1e9);
    s.extinction = o.number("extinction", s.extinction, 0, 1e9);
    s.albedo = o.number("albedo", s.albedo, 0, 1);
    s.anisotropy = o.number("anisotropy", s.anisotropy, -0.99, 0.99);
    s.skipEmptySpace = o.boolean("skipEmptySpace", s.skipEmptySpace);
    o.finish();
    return s;
}

} // namespace vfield
