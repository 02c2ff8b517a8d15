#include <vfield/mesh/mesh_source.h>

#include <vfield/core/error.h>
#include <vfield/mesh/tessellate.h>

#include <filesystem>

namespace vfield {

TerrainOptions terrainOptionsFromJson(const JsonValue& json)
{
    JsonObject o(json);
    TerrainOptions t;
    t.seed = uint64_t(o.integer("seed", int64_t(t.seed), 0, INT64_MAX));
    if (const auto size = o.find("size")) {
        const Vec2d v = size->asVec2();
        if (!(v[0] > 0 && v[1] > 0)) size->fail("expected two positive extents [x, z]");
        t.sizeX = v[0];
        t.sizeZ = v[1];
    }
    if (const auto cells = o.find("cells")) {
        const std::vector<JsonValue> v = cells->asArray();
        if (v.size() != 2) cells->fail("expected [cellsX, cellsZ]");
        t.cellsX = int(v[0].asInteger(1, 8192));
        t.cellsZ = int(v[1].asInteger(1, 8192));
    }
    t.amplitude = o.number("amplitude", t.amplitude, 0, 1e9);
    t.featureSize = o.number("featureSize", t.featureSize, 1e-9, 1e12);
    t.octaves = int(o.integer("octaves", t.octaves, 1, 16));
    t.roughness = o.number("roughness", t.roughness, 0, 1);
    t.baseThickness = o.number("baseThickness", t.baseThickness, 1e-9, 1e12);
    if (const auto carves = o.find("carves")) {
        for (const JsonValue& item : carves->asArray()) {
            JsonObject c(item);
            TerrainCarve carve;
            const JsonValue path = c.at("path");
            for (const JsonValue& point : path.asArray()) carve.path.push_back(point.asVec2());
            if (carve.path.size() < 2) path.fail("expected at least two [x, z] points");
            carve.halfWidth = c.number("halfWidth", carve.halfWidth, 1e-9, 1e12);
            carve.depth = c.number("depth", carve.depth, -1e12, 1e12);
            carve.wallSharpness = c.number("wallSharpness", carve.wallSharpness, 1, 100);
            c.finish();
            t.carves.push_back(carve);
        }
    }
    o.finish();
    return t;
}

MeshSource meshSourceFromJson(const JsonValue& json, const std::string& baseDir)
{
    JsonObject o(json);
    MeshSource source;
    int kinds = 0;
    if (const auto file = o.find("file")) {
        source.kind = MeshSource::Kind::File;
        const std::filesystem::path path(file->asString());
        source.path = path.is_absolute() ? path.string() : (std::filesystem::path(baseDir) / path).string();
        ++kinds;
    }
    if (const auto terrain = o.find("terrain")) {
        source.kind = MeshSource::Kind::Terrain;
        source.terrain = terrainOptionsFromJson(*terrain);
        ++kinds;
    }
    if (const auto sphere = o.find("sphere")) {
        JsonObject s(*sphere);
        source.kind = MeshSource::Kind::Sphere;
        source.sphere.center = s.vec3("center", source.sphere.center);
        source.sphere.radius = s.number("radius", source.sphere.radius, 1e-12, 1e12);
        source.sphere.subdivisions = int(s.integer("subdivisions", source.sphere.subdivisions, 0, 8));
        s.finish();
        ++kinds;
    }
    if (const auto box = o.find("box")) {
        JsonObject b(*box);
        source.kind = MeshSource::Kind::Box;
        source.box.min = b.vec3("min", source.box.min);
        source.box.max = b.vec3("max", source.box.max);
        for (int axis = 0; axis < 3; ++axis)
            if (!(source.box.max[axis] > source.box.min[axis])) box->fail("max must exceed min on every axis");
        b.finish();
        ++kinds;
    }
    if (kinds != 1) json.fail("expected exactly one of \"file\", \"terrain\", \"sphere\", \"box\"");
    source.tessellateEdge = o.number("tessellate", 0.0, 0.0, 1e12);
    o.finish();
    return source;
}

TriangleMesh makeMesh(const MeshSource& source, MeshLoadReport* report)
{
    TriangleMesh mesh;
    switch (source.kind) {
    case MeshSource::Kind::File:
        mesh = loadMesh(source.path, report);
        break;
    case MeshSource::Kind::Terrain:
        mesh = makeTerrain(source.terrain);
        break;
    case MeshSource::Kind::Sphere:
        mesh = makeSphere(source.sphere);
        break;
    case MeshSource::Kind::Box:
        mesh = makeBox(source.box);
        break;
    }
    if (source.tessellateEdge > 0) mesh = tessellate(mesh, source.tessellateEdge);
    return mesh;
}

} // namespace vfield
