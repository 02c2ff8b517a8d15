#include <vfield/render/render_settings.h>

#include <vfield/core/options.h>

#include <cmath>

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
    requireNumber("hazeDistance", hazeDistance, 0.0, 1e12);
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
    requireNumber("backAnisotropy", backAnisotropy, -0.99, 0.99);
    requireNumber("backWeight", backWeight, 0.0, 1.0);
}

double MediumSettings::phase(double cosTheta) const
{
    const double forward = henyeyGreenstein(cosTheta, anisotropy);
    return backWeight > 0.0 ? (1.0 - backWeight) * forward + backWeight * henyeyGreenstein(cosTheta, backAnisotropy) : forward;
}

double henyeyGreenstein(double cosTheta, double g)
{
    const double denominator = 1.0 + g * g - 2.0 * g * cosTheta;
    return (1.0 - g * g) / (4.0 * M_PI * denominator * std::sqrt(denominator));
}

void MultipleScattering::validate() const
{
    requireInteger("octaves", octaves, 1, 8);
    requireNumber("scatteringFalloff", scatteringFalloff, 0.0, 1.0);
    requireNumber("extinctionFalloff", extinctionFalloff, 0.0, 1.0);
    requireNumber("eccentricityFalloff", eccentricityFalloff, 0.0, 1.0);
    requireNumber("skyScatteringFalloff", skyScatteringFalloff, 0.0, 1.0);
}

void IntegratorSettings::validate() const
{
    requireInteger("maxBounces", maxBounces, 1, 1000000);
    requireNumber("volumeStep", volumeStep, 1e-6, 1e9);
    validatePart("multipleScattering", multipleScattering);
}

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
        s.hazeDistance = o.number("hazeDistance", s.hazeDistance);
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
    medium.backAnisotropy = o.number("backAnisotropy", medium.backAnisotropy);
    medium.backWeight = o.number("backWeight", medium.backWeight);
    IntegratorSettings& integrator = settings.integrator;
    const bool reference = integrator.kind == IntegratorKind::Reference;
    integrator.kind = o.choice("integrator", reference ? "reference" : "fast", {"fast", "reference"}) == "reference"
                          ? IntegratorKind::Reference
                          : IntegratorKind::Fast;
    integrator.maxBounces = o.integer("maxBounces", integrator.maxBounces);
    integrator.volumeStep = o.number("volumeStep", integrator.volumeStep);
    integrator.skipEmptySpace = o.boolean("skipEmptySpace", integrator.skipEmptySpace);
    const bool preview = settings.povrayQuality == PovrayQuality::Preview;
    settings.povrayQuality = o.choice("povrayQuality", preview ? "preview" : "final", {"final", "preview"}) == "preview"
                                 ? PovrayQuality::Preview
                                 : PovrayQuality::Final;
    if (const auto octaves = o.find("multipleScattering"))
        integrator.multipleScattering = readOptions<MultipleScattering>(*octaves, [](JsonObject& m, MultipleScattering& v) {
            v.octaves = m.integer("octaves", v.octaves);
            v.scatteringFalloff = m.number("scatteringFalloff", v.scatteringFalloff);
            v.extinctionFalloff = m.number("extinctionFalloff", v.extinctionFalloff);
            v.eccentricityFalloff = m.number("eccentricityFalloff", v.eccentricityFalloff);
            v.skyScatteringFalloff = m.number("skyScatteringFalloff", v.skyScatteringFalloff);
        });
    o.finish();
    validateAt(json, [&] {
        image.validate();
        medium.validate();
        integrator.validate();
    });
}

} // namespace vfield
