#include <vfield/mesh/mesh_source.h>

#include <vfield/core/options.h>
#include <vfield/mesh/tessellate.h>

#include <filesystem>

namespace vfield {

void MeshSource::validate() const
{
    requireNumber("tessellate", tessellateEdge, 0.0, 1e12);
    switch (kind) {
    case Kind::File:
        break;
    case Kind::Terrain:
        validatePart("terrain", terrain);
        break;
    case Kind::Heightmap:
        validatePart("heightmap", heightmap);
        break;
    case Kind::Sphere:
        validatePart("sphere", sphere);
        break;
    case Kind::Box:
        validatePart("box", box);
        break;
    }
}

namespace {

/// A heightfield's optional "cells": [cellsX, cellsZ].
void readCells(JsonObject& o, int& cellsX, int& cellsZ)
{
    if (const auto cells = o.find("cells")) {
        const std::vector<JsonValue> v = cells->asArray();
        if (v.size() != 2) cells->fail("expected [cellsX, cellsZ]");
        cellsX = v[0].asInt();
        cellsZ = v[1].asInt();
    }
}

/// The "terrain" object; its limits are TerrainOptions::validate's.
TerrainOptions terrainOptionsFromJson(const JsonValue& json)
{
    JsonObject o(json);
    TerrainOptions t;
    t.seed = o.unsignedInteger("seed", t.seed);
    if (const auto size = o.find("size")) {
        const Vec2d v = size->asVec2();
        t.sizeX = v[0];
        t.sizeZ = v[1];
    }
    readCells(o, t.cellsX, t.cellsZ);
    t.amplitude = o.number("amplitude", t.amplitude);
    t.featureSize = o.number("featureSize", t.featureSize);
    t.octaves = o.integer("octaves", t.octaves);
    t.roughness = o.number("roughness", t.roughness);
    const bool ridged = t.style == TerrainStyle::Ridged;
    t.style =
        o.choice("style", ridged ? "ridged" : "fbm", {"fbm", "ridged"}) == "ridged" ? TerrainStyle::Ridged : TerrainStyle::Fbm;
    t.erosion = o.number("erosion", t.erosion);
    t.baseThickness = o.number("baseThickness", t.baseThickness);
    if (const auto carves = o.find("carves")) {
        for (const JsonValue& item : carves->asArray()) {
            JsonObject c(item);
            TerrainCarve carve;
            for (const JsonValue& point : c.at("path").asArray()) carve.path.push_back(point.asVec2());
            carve.halfWidth = c.number("halfWidth", carve.halfWidth);
            carve.depth = c.number("depth", carve.depth);
            if (const auto floor = c.find("floorHeight")) carve.floorHeight = floor->asNumber();
            carve.wallSharpness = c.number("wallSharpness", carve.wallSharpness);
            carve.wallRoughness = c.number("wallRoughness", carve.wallRoughness);
            c.finish();
            t.carves.push_back(carve);
        }
    }
    o.finish();
    return t;
}

} // namespace

MeshSource meshSourceFromJson(const JsonValue& json, const std::string& baseDir)
{
    return readOptions<MeshSource>(json, [&](JsonObject& o, MeshSource& source) {
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
        if (const auto heightmap = o.find("heightmap")) {
            source.kind = MeshSource::Kind::Heightmap;
            source.heightmap = readOptions<HeightmapOptions>(*heightmap, [&](JsonObject& h, HeightmapOptions& v) {
                const std::filesystem::path path(h.at("file").asString());
                v.path = path.is_absolute() ? path.string() : (std::filesystem::path(baseDir) / path).string();
                const Vec2d size = h.at("size").asVec2();
                v.sizeX = size[0];
                v.sizeZ = size[1];
                v.heightScale = h.number("heightScale", v.heightScale);
                readCells(h, v.cellsX, v.cellsZ);
                v.baseThickness = h.number("baseThickness", v.baseThickness);
            });
            ++kinds;
        }
        if (const auto sphere = o.find("sphere")) {
            source.kind = MeshSource::Kind::Sphere;
            source.sphere = readOptions<SphereOptions>(*sphere, [](JsonObject& s, SphereOptions& v) {
                v.center = s.vec3("center", v.center);
                v.radius = s.number("radius", v.radius);
                v.subdivisions = s.integer("subdivisions", v.subdivisions);
            });
            ++kinds;
        }
        if (const auto box = o.find("box")) {
            source.kind = MeshSource::Kind::Box;
            source.box = readOptions<BoxOptions>(*box, [](JsonObject& b, BoxOptions& v) {
                v.min = b.vec3("min", v.min);
                v.max = b.vec3("max", v.max);
            });
            ++kinds;
        }
        if (kinds != 1) json.fail("expected exactly one of \"file\", \"terrain\", \"heightmap\", \"sphere\", \"box\"");
        source.tessellateEdge = o.number("tessellate", 0.0);
    });
}

TriangleMesh makeMesh(const MeshSource& source, MeshLoadReport* report)
{
    source.validate();
    TriangleMesh mesh;
    switch (source.kind) {
    case MeshSource::Kind::File:
        mesh = loadMesh(source.path, report);
        break;
    case MeshSource::Kind::Terrain:
        mesh = makeTerrain(source.terrain);
        break;
    case MeshSource::Kind::Heightmap:
        mesh = makeHeightmapTerrain(source.heightmap);
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
