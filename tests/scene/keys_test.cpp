// Values on keys (vfield/core/animation.h): how a keyed value is read,
// checked, interpolated, hashed, written and documented.

#include <vfield/core/field_visitors.h>
#include <vfield/scene/scene.h>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

using namespace vfield;

namespace {

Scene keyedScene(const std::string& keys)
{
    return parseScene(R"({"version": 1, "objects": [{"name": "a", "mesh": {"box": {}}}])" + keys + "}", "s.json");
}

KeyTrack scalarTrack(std::vector<double> frames, std::vector<double> values, Interpolation interpolation)
{
    return KeyTrack(std::move(frames), std::move(values), 1, interpolation, false);
}

double scalarAt(const KeyTrack& track, double frame) { return keyedValue<double>(track, frame); }

} // namespace

TEST_CASE("keys: every interpolation passes exactly through its keys, fractional frames included", "[keys]")
{
    const std::vector<double> frames = {1.0, 12.5, 30.0, 31.0}, values = {2.0, -1.0, 4.0, 4.5};
    for (const Interpolation interpolation : {Interpolation::Linear, Interpolation::Smooth, Interpolation::Step}) {
        const KeyTrack track = scalarTrack(frames, values, interpolation);
        for (std::size_t i = 0; i < frames.size(); ++i) CHECK(scalarAt(track, frames[i]) == values[i]);
        // Before the first key the first value holds, after the last the last.
        CHECK(scalarAt(track, -100.0) == 2.0);
        CHECK(scalarAt(track, 1000.0) == 4.5);
    }
}

TEST_CASE("keys: linear goes straight between keys, step holds each key until the next", "[keys]")
{
    const KeyTrack linear = scalarTrack({10.0, 20.0}, {1.0, 3.0}, Interpolation::Linear);
    CHECK(scalarAt(linear, 12.5) == Approx(1.5).margin(1e-15));
    CHECK(scalarAt(linear, 15.0) == Approx(2.0).margin(1e-15));
    const KeyTrack step = scalarTrack({10.0, 20.0, 30.0}, {1.0, 3.0, -2.0}, Interpolation::Step);
    CHECK(scalarAt(step, 19.999) == 1.0);
    CHECK(scalarAt(step, 20.0) == 3.0);
    CHECK(scalarAt(step, 29.5) == 3.0);
}

TEST_CASE("keys: smooth never overshoots its keys, is flat at peaks and at the ends, and stays monotone between keys", "[keys]")
{
    // A rise, a plateau-like step, a peak and a fall: where a Catmull-Rom would overshoot.
    const std::vector<double> frames = {0.0, 10.0, 11.0, 20.0, 40.0}, values = {0.0, 1.0, 1.05, 3.0, 0.0};
    const KeyTrack smooth = scalarTrack(frames, values, Interpolation::Smooth);
    for (std::size_t i = 0; i + 1 < frames.size(); ++i) {
        const double low = std::min(values[i], values[i + 1]), high = std::max(values[i], values[i + 1]);
        const double direction = values[i + 1] > values[i] ? 1.0 : -1.0;
        double previous = values[i];
        for (int k = 1; k <= 200; ++k) {
            const double v = scalarAt(smooth, frames[i] + (frames[i + 1] - frames[i]) * k / 200.0);
            CHECK(v >= low - 1e-12);
            CHECK(v <= high + 1e-12);
            CHECK((v - previous) * direction >= -1e-12);
            previous = v;
        }
    }
    // Flat at the peak (frame 20) and at both ends: the slope there is zero.
    const double h = 1e-4;
    for (const double flat : {0.0 + h, 20.0, 40.0 - h})
        CHECK(std::abs(scalarAt(smooth, flat + h) - scalarAt(smooth, flat - h)) / (2.0 * h) < 1e-3);
    // Eases in: a quarter of the way into the first interval it has gone less than a quarter of the way.
    CHECK(scalarAt(smooth, 2.5) < 0.25);
    CHECK(scalarAt(smooth, 2.5) > 0.0);
}

TEST_CASE("keys: a keyed direction is a unit vector at and between its keys", "[keys]")
{
    const KeyTrack track({0.0, 10.0}, {2.0, 0.0, 0.0, 0.0, 0.0, 5.0}, 3, Interpolation::Linear, true);
    CHECK((keyedValue<Vec3d>(track, 0.0) - Vec3d(1, 0, 0)).length() < 1e-15);
    const Vec3d half = keyedValue<Vec3d>(track, 5.0);
    CHECK(half.length() == Approx(1.0).epsilon(1e-14));
    CHECK((half - Vec3d(1, 0, 1).unit()).length() < 1e-14);
}

TEST_CASE("keys: a scene's keyed values are read, resolved per frame and checked at their JSON pointers", "[keys]")
{
    const Scene scene = keyedScene(R"(, "sun": {"intensity": {"keys": [[1, 2], [11, 4]]},
        "direction": {"keys": [[1, [0, 1, 0]], [11, [1, 0, 0]]], "interpolation": "smooth"}},
        "camera": {"fovDegrees": {"keys": [[1, 30], [5.5, 60]], "interpolation": "step"}},
        "fields": [{"acceleration": {"keys": [[1, [0, 0, 0]], [25, [24, 0, 0]]]}}],
        "turbulence": [{"strength": {"keys": [[1, 0], [2, 1]]}}])");
    // The member holds the first key's value; the frame's settings hold the frame's.
    CHECK(scene.render.sun.intensity == 2.0);
    CHECK(scene.render.at(6.0).sun.intensity == Approx(3.0));
    CHECK(scene.render.at(6.0).sun.direction.length() == Approx(1.0));
    CHECK(scene.render.at(5.0).camera.fovDegrees == 30.0);
    CHECK(scene.render.at(5.5).camera.fovDegrees == 60.0);
    CHECK(scene.simulation.fields[0].accelerationAt(Vec3d(0.0), 13.0) == Vec3d(12, 0, 0));
    // At a frame, a struct is as a scene of constants gives it: no keys left.
    CHECK(scene.render.at(6.0).sun.animation.empty());
    CHECK(!scene.render.at(6.0).camera.moves());

    CHECK_THROWS_WITH(keyedScene(R"(, "sun": {"intensity": {"keys": [[1, 2], [1, 4]]}})"),
                      Catch::StartsWith("s.json: /sun/intensity/keys/1/0: expected frames in increasing order"));
    CHECK_THROWS_WITH(keyedScene(R"(, "sun": {"intensity": {"keys": [[1, 2], [3, -4]]}})"),
                      Catch::StartsWith("s.json: /sun/intensity/keys/1/1:"));
    CHECK_THROWS_WITH(keyedScene(R"(, "sun": {"intensity": {"keys": []}})"),
                      Catch::StartsWith("s.json: /sun/intensity/keys: expected at least one key"));
    CHECK_THROWS_WITH(keyedScene(R"(, "sun": {"intensity": {"keys": [[1]]}})"),
                      Catch::StartsWith("s.json: /sun/intensity/keys/0: expected a key [frame, value]"));
    CHECK_THROWS_WITH(keyedScene(R"(, "sun": {"intensity": {"keys": [[1, 2]], "interpolation": "bezier"}})"),
                      Catch::StartsWith("s.json: /sun/intensity/interpolation:"));
    CHECK_THROWS_WITH(keyedScene(R"(, "sun": {"direction": {"keys": [[1, [0, 0, 0]]]}})"),
                      Catch::StartsWith("s.json: /sun/direction/keys/0/1: expected a non-zero vector"));
    // A value the declarations do not mark animatable takes no keys.
    CHECK_THROWS_WITH(keyedScene(R"(, "render": {"samplesPerPixel": {"keys": [[1, 2], [5, 8]]}})"),
                      Catch::StartsWith("s.json: /render/samplesPerPixel:"));
    CHECK_THROWS_WITH(keyedScene(R"(, "clouds": [{"count": {"keys": [[1, 2], [5, 8]]}}])"),
                      Catch::StartsWith("s.json: /clouds/0/count:"));
}

TEST_CASE("keys: keys enter the content hash, and a scene written out reads back the same", "[keys]")
{
    const Scene constant = keyedScene(R"(, "sun": {"intensity": 2})");
    const Scene keyed = keyedScene(R"(, "sun": {"intensity": {"keys": [[1, 2], [11, 4]], "interpolation": "smooth"}})");
    const Scene otherKeys = keyedScene(R"(, "sun": {"intensity": {"keys": [[1, 2], [11, 5]], "interpolation": "smooth"}})");
    CHECK(constant.render.hash() != keyed.render.hash());
    CHECK(keyed.render.hash() != otherKeys.render.hash());

    const nlohmann::json written = fieldsToJson(keyed.render.sun);
    CHECK(written["intensity"]["interpolation"] == "smooth");
    CHECK(written["intensity"]["keys"][1][1] == 4.0);
    const SunSettings reread = readFields<SunSettings>(parseJson(written.dump(), "written.json"));
    ContentHash a, b;
    hashFields(a, keyed.render.sun);
    hashFields(b, reread);
    CHECK(a.value() == b.value());
}

TEST_CASE("keys: the key tables mark what is animatable", "[keys]")
{
    const std::vector<FieldTable> tables = describeFields<RenderSettings>();
    const auto typeOf = [&](const std::string& title, const std::string& key) {
        for (const FieldTable& table : tables)
            if (table.title == title)
                for (const FieldDoc& row : table.rows)
                    if (row.key == key) return row.type;
        FAIL("no row " << title << " " << key);
        return std::string();
    };
    CHECK(typeOf("sun", "intensity") == "number or keys");
    CHECK(typeOf("camera", "position") == "[x, y, z] or keys");
    CHECK(typeOf("render", "samplesPerPixel") == "integer");
}
