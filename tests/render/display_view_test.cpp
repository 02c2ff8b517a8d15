// How scene-linear light is shown: vfield's OpenColorIO config (its Standard
// and Filmic views), the exposure, and $OCIO.

#include "test_meshes.h"

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>
#include <vfield/render/display_view.h>

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdlib>
#include <string>

using namespace vfield;

namespace {

using Rgb = std::array<float, 3>;

Rgb shown(const DisplayView& view, Rgb linear)
{
    view.apply(linear.data(), 1);
    return linear;
}

DisplayView viewNamed(const std::string& name, double exposure = 0.0) { return DisplayView(ViewSettings{name, exposure}); }

double srgb(double v)
{
    v = std::clamp(v, 0.0, 1.0);
    return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
}

double srgbToLinear(double e) { return e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4); }

/// Oklab's hue angle (degrees) and chroma of a linear Rec.709 colour.
std::pair<double, double> oklabHue(const Rgb& c)
{
    const double l = std::cbrt(0.4122214708 * c[0] + 0.5363325363 * c[1] + 0.0514459929 * c[2]);
    const double m = std::cbrt(0.2119034982 * c[0] + 0.6806995451 * c[1] + 0.1073969566 * c[2]);
    const double s = std::cbrt(0.0883024619 * c[0] + 0.2817188376 * c[1] + 0.6299787005 * c[2]);
    const double a = 1.9779984951 * l - 2.4285922050 * m + 0.4505937099 * s;
    const double b = 0.0259040371 * l + 0.7827717662 * m - 0.8086757660 * s;
    return {std::atan2(b, a) * 180.0 / M_PI, std::hypot(a, b)};
}

/// $OCIO set to a config while it lives, then as it was.
class ScopedOcio {
public:
    explicit ScopedOcio(const std::string& config) : mOld(std::getenv("OCIO") ? std::getenv("OCIO") : "")
    {
        ::setenv("OCIO", config.c_str(), 1);
    }
    ~ScopedOcio() { mOld.empty() ? ::unsetenv("OCIO") : ::setenv("OCIO", mOld.c_str(), 1); }

private:
    std::string mOld;
};

} // namespace

TEST_CASE("display view: Standard is the sRGB encoding of the light clipped to [0, 1]", "[render][colour]")
{
    const DisplayView standard = viewNamed("Standard");
    for (float v : {0.0f, 0.001f, 0.0031308f, 0.01f, 0.18f, 0.5f, 0.9f, 1.0f, 1.5f, 40.0f}) {
        const Rgb out = shown(standard, {v, 0.5f * v, 0.25f * v});
        CHECK(out[0] == Approx(srgb(v)).margin(1e-5));
        CHECK(out[1] == Approx(srgb(0.5 * v)).margin(1e-5));
        CHECK(out[2] == Approx(srgb(0.25 * v)).margin(1e-5));
    }
}

TEST_CASE("display view: Filmic shows mid grey as Standard does, with more contrast, and rolls highlights off without clipping",
          "[render][colour]")
{
    const DisplayView filmic = viewNamed("Filmic"), standard = viewNamed("Standard");
    const auto grey = [](const DisplayView& view, double v) { return shown(view, {float(v), float(v), float(v)})[0]; };
    CHECK(grey(filmic, 0.18) == Approx(grey(standard, 0.18)).margin(1e-3));
    // A stop either side of mid grey lies further apart than Standard shows it.
    CHECK(grey(filmic, 0.36) - grey(filmic, 0.09) > 1.5 * (grey(standard, 0.36) - grey(standard, 0.09)));
    // Brighter, it keeps rising but stays under the last 8-bit step until
    // the light is 12 times scene white: the sunlit heaps that Standard
    // shows flat white keep their shape. Darker, it keeps falling towards black.
    float last = 0.0f;
    for (double v = 1e-4; v < 12.0; v *= 1.1) {
        const float out = grey(filmic, v);
        CHECK(out > last);
        CHECK(out < 254.5f / 255.0f);
        last = out;
    }
    CHECK(grey(filmic, 0.0) == 0.0f);
    CHECK(grey(filmic, 1e-4) < 1.0f / 255.0f);
}

TEST_CASE("display view: Filmic keeps a colour's hue as it rolls it off to white", "[render][colour]")
{
    const DisplayView filmic = viewNamed("Filmic");
    // The sun's, the sky's and a cloud's shaded colour, and saturated primaries.
    for (const Rgb& colour : {Rgb{1.0f, 0.75f, 0.5f}, Rgb{0.35f, 0.55f, 1.0f}, Rgb{0.6f, 0.68f, 0.85f}, Rgb{1.0f, 0.1f, 0.05f},
                              Rgb{0.1f, 1.0f, 0.1f}, Rgb{0.05f, 0.1f, 1.0f}}) {
        const double hue = oklabHue(colour).first;
        double saturationBefore = 1e9;
        for (double stops = -4.0; stops <= 5.0; stops += 0.25) {
            const float scale = float(std::exp2(stops));
            Rgb out = shown(filmic, {scale * colour[0], scale * colour[1], scale * colour[2]});
            for (float& c : out) c = float(srgbToLinear(c));
            const auto [outHue, chroma] = oklabHue(out);
            INFO("colour " << colour[0] << " " << colour[1] << " " << colour[2] << " at " << stops << " stops");
            if (chroma > 0.01) CHECK(std::abs(std::remainder(outHue - hue, 360.0)) < 2.0);
            // Brighter, towards white: the chroma relative to the lightness never grows past the shoulder.
            const double lightness = std::cbrt(0.2126 * out[0] + 0.7152 * out[1] + 0.0722 * out[2]);
            if (stops > 1.0) CHECK(chroma / lightness <= saturationBefore + 1e-2);
            saturationBefore = stops > 1.0 ? chroma / lightness : 1e9;
        }
    }
}

TEST_CASE("display view: exposure scales the light before the view", "[render][colour]")
{
    const DisplayView brighter = viewNamed("Filmic", 1.0), filmic = viewNamed("Filmic");
    const Rgb a = shown(brighter, {0.2f, 0.5f, 1.5f}), b = shown(filmic, {0.4f, 1.0f, 3.0f});
    for (int c = 0; c < 3; ++c) CHECK(a[c] == b[c]);
}

TEST_CASE("display view: a view the config lacks is refused, naming render/view and the views there are", "[render][colour]")
{
    try {
        viewNamed("AgX");
        FAIL("an unknown view was taken");
    } catch (const OptionError& e) {
        CHECK(e.key() == "render/view");
        CHECK_THAT(e.detail(), Catch::Contains("(Filmic, Standard, Raw), got 'AgX'"));
    }
}

TEST_CASE("display view: $OCIO's config is used instead of vfield's when it is set", "[render][colour]")
{
    // A config of one display whose only view halves the light.
    const std::string dir = test::scratchDir("display-view-ocio");
    writeTextAtomically(dir + "/config.ocio", R"(ocio_profile_version: 2
roles: {default: lin, scene_linear: lin}
file_rules: [!<Rule> {name: Default, colorspace: default}]
displays:
  Half: [!<View> {name: Half, colorspace: half}]
colorspaces:
  - !<ColorSpace> {name: lin}
  - !<ColorSpace>
    name: half
    from_scene_reference: !<MatrixTransform> {matrix: [0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 1]}
)");
    const ScopedOcio ocio(dir + "/config.ocio");
    CHECK(displayConfigPath() == dir + "/config.ocio");
    const DisplayView half = viewNamed("Half");
    CHECK(half.display() == "Half");
    CHECK(shown(half, {0.5f, 2.0f, 8.0f}) == Rgb{0.25f, 1.0f, 4.0f});
    CHECK_THROWS_AS(viewNamed("Filmic"), OptionError);
}

TEST_CASE("display view: a config that cannot be read is an error naming its file", "[render][colour]")
{
    const std::string dir = test::scratchDir("display-view-bad-config");
    writeTextAtomically(dir + "/config.ocio", "ocio_profile_version: 2\ncolorspaces: [\n");
    const ScopedOcio ocio(dir + "/config.ocio");
    try {
        viewNamed("Filmic");
        FAIL("a broken config was read");
    } catch (const FileError& e) {
        CHECK(e.path() == dir + "/config.ocio");
        CHECK(std::string(e.what()).find('\n') == std::string::npos);
    }
}
