#include <vfield/core/error.h>
#include <vfield/core/json.h>
#include <vfield/core/options.h>

#include <catch2/catch.hpp>

using namespace vfield;

TEST_CASE("json: a syntax error names its line and column", "[json]")
{
    CHECK_THROWS_WITH(parseJson("{\n  \"a\": 1,\n  \"b\": ]\n}", "s.json"),
                      Catch::StartsWith("s.json: line 3, column 8: JSON syntax error"));
}

TEST_CASE("json: documents nested deeper than the limit are refused before parsing", "[json]")
{
    // 100,000 levels overflowed the stack; the limit holds for arrays and objects alike.
    const std::string arrays = std::string(100000, '[') + std::string(100000, ']');
    CHECK_THROWS_WITH(parseJson(arrays, "deep.json"),
                      "deep.json: line 1, column 257: JSON nested deeper than 256 arrays and objects");
    std::string objects;
    for (int i = 0; i < 100000; ++i) objects += "{\"a\":";
    objects += "1" + std::string(100000, '}');
    CHECK_THROWS_WITH(parseJson(objects, "deep.json"), Catch::StartsWith("deep.json: line 1, column "));
    CHECK_THROWS_AS(parseJson(objects, "deep.json"), ParseError);
    // Brackets in strings do not nest, and the limit itself parses.
    CHECK_NOTHROW(parseJson("[\"" + std::string(1000, '[') + "\"]", "s.json"));
    CHECK_NOTHROW(parseJson(std::string(256, '[') + std::string(256, ']'), "s.json"));
}

TEST_CASE("json: an option out of range is reported at its JSON path", "[json]")
{
    const JsonValue root = parseJson(R"({"clouds": [{"count": -5}]})", "cloud.json");
    JsonObject clouds(root);
    const JsonValue first = clouds.at("clouds").asArray()[0];
    JsonObject cloud(first);
    const int64_t count = cloud.integer64("count", 1);
    CHECK_THROWS_WITH(validateAt(first, [&] { requireInteger("count", count, 1, 1000); }),
                      "cloud.json: /clouds/0/count: expected a positive integer, got -5");
    CHECK_THROWS_WITH(validateAt(root, [&] { requireNumber("clouds/0/count", double(count), 0.0, 1.0); }),
                      "cloud.json: /clouds/0/count: expected a number within [0, 1], got -5");
}

TEST_CASE("json: a key nobody reads is an error naming it", "[json]")
{
    const JsonValue root = parseJson(R"({"frames": {"start": 1, "ends": 10}})", "s.json");
    JsonObject o(root);
    JsonObject frames(o.at("frames"));
    frames.integer("start", 1);
    frames.integer("end", 1);
    CHECK_THROWS_WITH(frames.finish(), "s.json: /frames/ends: unknown key \"ends\"");
}

TEST_CASE("json: typed reads check kinds", "[json]")
{
    CHECK_THROWS_WITH(parseJson(R"({"d": 1e400})", "t.json"), Catch::StartsWith("t.json: document: JSON error: number overflow"));
    const JsonValue root = parseJson(R"({"a": 1.5, "b": "x", "c": [1, 2]})", "t.json");
    JsonObject o(root);
    CHECK_THROWS_WITH(o.integer("a", 0), Catch::Contains("/a: expected an integer, got 1.5"));
    CHECK_THROWS_WITH(o.number("b", 0), Catch::Contains("/b: expected a number"));
    CHECK_THROWS_WITH(o.vec3("c", Vec3d(0.0)), Catch::Contains("/c: expected [x, y, z]"));
    CHECK_THROWS_WITH(o.choice("b", "p", {"p", "q"}), Catch::Contains("expected one of \"p\", \"q\", got \"x\""));
    CHECK(o.number("a", 0) == 1.5);
}
