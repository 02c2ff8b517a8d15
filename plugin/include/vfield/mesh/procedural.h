#pragma once
/// @file procedural.h
/// Procedural meshes -> TriangleMesh (object space, y up, right-handed): a
/// heightfield terrain closed into a solid, a sphere and a box. All are closed
/// and wound outward, so inside and outside are defined for signed distances.

#include <vfield/core/fields.h>
#include <vfield/mesh/triangle_mesh.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace vfield {

/// A groove (or, with negative depth, a ridge) cut into a terrain along a path
/// in the ground plane. A path of three or more points is followed as a smooth
/// Catmull-Rom curve, so a few points describe a winding canyon. With a
/// floorHeight the carve levels the ground to that height instead: a canyon
/// through rugged mountains gets an even floor, its walls keep the relief.
struct CarveSettings {
    std::vector<Vec2d> path;
    double halfWidth = 10.0;
    double depth = 10.0;
    double wallSharpness = 1.0;
    double wallRoughness = 0.0; ///< 0 keeps the walls parallel to the path
    /// The profile blends the levelled centre line into the ground around.
    std::optional<double> floorHeight;

    /// Throws OptionError naming the first option out of range.
    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("path", self.path)
                  .required()
                  .doc("[x, z] points, two or more; three or more are followed as a smooth Catmull-Rom curve"));
        visit(field("halfWidth", self.halfWidth)
                  .range(1e-9, 1e12)
                  .unit("world units")
                  .doc("distance from the path at which the cut ends"));
        visit(field("depth", self.depth)
                  .range(-1e12, 1e12)
                  .unit("world units")
                  .doc("how far the path's centre line is lowered; negative raises a ridge"));
        visit(field("wallSharpness", self.wallSharpness)
                  .range(1, 100)
                  .doc("1: a smooth valley; larger: steeper walls and a flatter floor"));
        visit(field("wallRoughness", self.wallRoughness)
                  .atLeast(0)
                  .unit("world units, at most halfWidth")
                  .doc("how far the walls wander in and out (fBm at the scale of halfWidth added to the distance from the path): "
                       "buttresses and alcoves"));
        visit(field("floorHeight", self.floorHeight)
                  .range(-1e12, 1e12)
                  .unit("world units")
                  .doc("levels the path to this height, cutting and filling (depth is then unused): an even canyon floor through "
                       "rugged mountains"));
    }
};

/// The noise a terrain's heights come from.
enum class TerrainStyle {
    Fbm,   ///< rolling hills: fractional Brownian motion
    Ridged ///< mountains: Musgrave's ridged multifractal, sharp crests and smooth valleys
};
inline constexpr EnumName<TerrainStyle> kTerrainStyleNames[] = {{TerrainStyle::Fbm, "fbm"}, {TerrainStyle::Ridged, "ridged"}};
constexpr const auto& enumNames(TerrainStyle) { return kTerrainStyleNames; }

/// A heightfield over [-sizeX/2, sizeX/2] x [-sizeZ/2, sizeZ/2], heights along +y.
/// height(x, z) = amplitude * erode(noise(x / featureSize, z / featureSize)) - carves,
/// with the noise in about [0, 1] and erode(n) = n^(1 + 3 erosion), which widens
/// and flattens the valley floors as erosion's deposits would (a height curve,
/// not a simulation of water).
/// The solid is the surface, four vertical skirts and a bottom plane
/// `baseThickness` below the lowest surface point.
struct TerrainSettings {
    static constexpr int kMaxCellsPerAxis = 8192;
    static constexpr double kMaxCells = 64e6; ///< in all: cellsX x cellsZ

    uint64_t seed = 1;
    double sizeX = 200.0;
    double sizeZ = 200.0;
    int cellsX = 128;
    int cellsZ = 128;
    double amplitude = 30.0;
    double featureSize = 80.0;
    int octaves = 5;
    double roughness = 0.5;
    TerrainStyle style = TerrainStyle::Fbm;
    double erosion = 0.0; ///< 0 leaves the noise as it is
    double baseThickness = 10.0;
    std::vector<CarveSettings> carves;

    /// Throws OptionError naming the first option out of range (keys as in a
    /// scene file: "size/0", "cells/1", "carves/2/halfWidth", ...).
    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("seed", self.seed).doc("noise seed: the same seed gives the same terrain on every machine"));
        visit(field("size", pairOf(self.sizeX, self.sizeZ, "x, z"))
                  .range(1e-9, 1e12)
                  .unit("world units")
                  .doc("extent, centred on the origin"));
        visit(field("cells", pairOf(self.cellsX, self.cellsZ, "cellsX, cellsZ"))
                  .range(1, kMaxCellsPerAxis)
                  .doc("grid cells, 64 million at most in all; two triangles each"));
        visit(field("amplitude", self.amplitude)
                  .range(0, 1e9)
                  .unit("world units")
                  .doc("height of the noise: heights span about [0, amplitude]"));
        visit(field("featureSize", self.featureSize)
                  .range(1e-9, 1e12)
                  .unit("world units")
                  .doc("wavelength of the coarsest octave"));
        visit(field("octaves", self.octaves).range(1, 16).doc("noise octaves"));
        visit(field("roughness", self.roughness).range(0, 1).doc("amplitude ratio of successive octaves"));
        visit(field("style", self.style)
                  .doc("fBm: rolling hills; ridged: Musgrave's ridged multifractal, mountains with sharp crests"));
        visit(
            field("erosion", self.erosion).range(0, 1).doc("valley flattening: heights become n^(1 + 3 erosion) of the noise n"));
        visit(field("baseThickness", self.baseThickness)
                  .range(1e-9, 1e12)
                  .unit("world units")
                  .doc("depth of the solid below the lowest surface point"));
        visit(field("carves", self.carves).doc("valleys, canyons and ridges, applied in order"));
    }
};

/// The surface height at (x, z): the same function the mesh samples.
double terrainHeight(const TerrainSettings& options, double x, double z);
TriangleMesh makeTerrain(const TerrainSettings& options);

/// A terrain from an elevation image (a 16-bit PNG, TIFF or EXR; first
/// channel), closed into a solid as makeTerrain's. The image spans
/// [-sizeX/2, sizeX/2] x [-sizeZ/2, sizeZ/2] corner pixel to corner pixel,
/// its rows along +z; heights are heightScale x the pixel value (integer
/// formats read as [0, 1]), sampled bilinearly at the grid's points.
struct HeightmapSettings {
    /// Heights, pixel value x heightScale, must lie within +-this many world
    /// units: a real elevation model is thousands of units high, a broken one
    /// 1e30, which no float mesh can hold.
    static constexpr double kMaxHeight = 1e6;

    std::string path; ///< a scene file's path is resolved against its folder
    double sizeX = 200.0;
    double sizeZ = 200.0;
    double heightScale = 50.0;
    int cellsX = 0;
    int cellsZ = 0;
    double baseThickness = 10.0;
    bool fillNoData = false;

    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("file", self.path)
                  .required()
                  .isPath()
                  .doc("the image (16-bit PNG, TIFF or EXR; its first channel), relative to the scene"));
        visit(field("size", pairOf(self.sizeX, self.sizeZ, "x, z"))
                  .required()
                  .range(1e-9, 1e12)
                  .unit("world units")
                  .doc("extent, centred on the origin"));
        visit(field("heightScale", self.heightScale).range(-1e9, 1e9).doc("world units per unit of pixel value"));
        visit(field("cells", pairOf(self.cellsX, self.cellsZ, "cellsX, cellsZ"))
                  .range(0, TerrainSettings::kMaxCellsPerAxis)
                  .defaultText("one per pixel")
                  .doc("grid cells; 0: one per pixel"));
        visit(field("baseThickness", self.baseThickness)
                  .range(1e-9, 1e12)
                  .unit("world units")
                  .doc("depth of the solid below its lowest point"));
        visit(field("fillNoData", self.fillNoData)
                  .doc("fill pixels that hold no number (NaN or infinite: no-data holes) from their nearest valid pixel; "
                       "otherwise such a pixel is refused, naming it"));
    }
};
/// Throws FileError naming the file and the first pixel (x, y) that holds no
/// number (unless fillNoData), or whose height lies beyond kMaxHeight.
TriangleMesh makeHeightmapTerrain(const HeightmapSettings& options);

struct SphereSettings {
    Vec3d center{0.0, 0.0, 0.0};
    double radius = 1.0;
    int subdivisions = 3;

    /// Throws OptionError naming the first option out of range.
    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("center", self.center).unit("world units").doc("centre"));
        visit(field("radius", self.radius).range(1e-12, 1e12).unit("world units").doc("radius"));
        visit(field("subdivisions", self.subdivisions).range(0, 8).doc("icosahedron subdivisions: 20 x 4^n triangles"));
    }
};
TriangleMesh makeSphere(const SphereSettings& options);

struct BoxSettings {
    Vec3d min{-1.0, -1.0, -1.0};
    Vec3d max{1.0, 1.0, 1.0};

    /// Throws OptionError unless max exceeds min on every axis.
    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("min", self.min).unit("world units").doc("lower corner"));
        visit(field("max", self.max).unit("world units").doc("upper corner, above min on every axis"));
    }
};
TriangleMesh makeBox(const BoxSettings& options);

} // namespace vfield
