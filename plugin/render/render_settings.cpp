#include <vfield/render/render_settings.h>

#include <vfield/core/options.h>

namespace vfield {

namespace {

void requireColor(const std::string& key, const Vec3d& color)
{
    require(color[0] >= 0 && color[1] >= 0 && color[2] >= 0, key, "expected a colour of three numbers >= 0");
}

} // namespace

void CameraSettings::validate() const
{
    require(up.length() > 0, "up", "expected a non-zero vector");
    requireNumber("fovDegrees", fovDegrees, 1e-3, 179.0);
    require(followObject.has_value() || (position - lookAt).length() > 0, "", "position and lookAt must differ");
}

void SunSettings::validate() const
{
    require(direction.length() > 0, "direction", "expected a non-zero vector");
    requireColor("color", color);
    requireNumber("intensity", intensity, 0.0, 1e6);
}

void SkySettings::validate() const
{
    requireColor("zenithColor", zenithColor);
    requireColor("horizonColor", horizonColor);
    requireNumber("intensity", intensity, 0.0, 1e6);
}

void ImageSettings::validate() const
{
    requireInteger("resolution/0", width, 1, kMaxResolution);
    requireInteger("resolution/1", height, 1, kMaxResolution);
    requireInteger("samplesPerPixel", samplesPerPixel, 1, 65536);
}

void MediumSettings::validate() const
{
    requireNumber("extinction", extinction, 0.0, 1e9);
    requireNumber("albedo", albedo, 0.0, 1.0);
    requireNumber("anisotropy", anisotropy, -0.99, 0.99);
}

void IntegratorSettings::validate() const { requireNumber("volumeStep", volumeStep, 1e-6, 1e9); }

void RenderSettings::validate() const
{
    validatePart("camera", camera);
    validatePart("sun", sun);
    validatePart("sky", sky);
    validatePart("render", image);
    validatePart("render", medium);
    validatePart("render", integrator);
}

CameraSettings cameraSettingsFromJson(const JsonValue& json)
{
    return readOptions<CameraSettings>(json, [&](JsonObject& o, CameraSettings& c) {
        c.position = o.vec3("position", c.position);
        c.lookAt = o.vec3("lookAt", c.lookAt);
        c.up = o.vec3("up", c.up);
        c.fovDegrees = o.number("fovDegrees", c.fovDegrees);
        if (const auto follow = o.find("follow")) {
            JsonObject f(*follow);
            c.followObject = f.at("object").asString();
            c.followOffset = f.vec3("offset", c.followOffset);
            f.finish();
        }
    });
}

SunSettings sunSettingsFromJson(const JsonValue& json)
{
    return readOptions<SunSettings>(json, [&](JsonObject& o, SunSettings& s) {
        s.direction = o.vec3("direction", s.direction);
        s.color = o.vec3("color", s.color);
        s.intensity = o.number("intensity", s.intensity);
    });
}

SkySettings skySettingsFromJson(const JsonValue& json)
{
    return readOptions<SkySettings>(json, [&](JsonObject& o, SkySettings& s) {
        s.zenithColor = o.vec3("zenithColor", s.zenithColor);
        s.horizonColor = o.vec3("horizonColor", s.horizonColor);
        s.intensity = o.number("intensity", s.intensity);
    });
}

void renderSectionFromJson(const JsonValue& json, RenderSettings& settings)
{
    JsonObject o(json);
    ImageSettings& image = settings.image;
    if (const auto resolution = o.find("resolution")) {
        const std::vector<JsonValue> wh = resolution->asArray();
        if (wh.size() != 2) resolution->fail("expected [width, height]");
        image.width = wh[0].asInt();
        image.height = wh[1].asInt();
    }
    image.samplesPerPixel = o.integer("samplesPerPixel", image.samplesPerPixel);
    image.transparentSky = o.boolean("transparentSky", image.transparentSky);
    MediumSettings& medium = settings.medium;
    medium.extinction = o.number("extinction", medium.extinction);
    medium.albedo = o.number("albedo", medium.albedo);
    medium.anisotropy = o.number("anisotropy", medium.anisotropy);
    IntegratorSettings& integrator = settings.integrator;
    integrator.volumeStep = o.number("volumeStep", integrator.volumeStep);
    integrator.skipEmptySpace = o.boolean("skipEmptySpace", integrator.skipEmptySpace);
    o.finish();
    validateAt(json, [&] {
        image.validate();
        medium.validate();
        integrator.validate();
    });
}

} // namespace vfield
