#include <vfield/mesh/procedural.h>

#include <vfield/core/field_visitors.h>
#include <vfield/core/image_file.h>
#include <vfield/core/noise.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <string>

namespace vfield {

namespace {

Vec2d catmullRom(const Vec2d& p0, const Vec2d& p1, const Vec2d& p2, const Vec2d& p3, double t)
{
    const double t2 = t * t, t3 = t2 * t;
    return 0.5 * ((2.0 * p1) + (p2 - p0) * t + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2 + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t3);
}

/// The carve's path as a dense polyline (a smooth curve through 3+ points).
std::vector<Vec2d> samplePath(const std::vector<Vec2d>& path)
{
    if (path.size() < 3) return path;
    constexpr int kSamplesPerSpan = 32;
    std::vector<Vec2d> dense;
    for (std::size_t i = 0; i + 1 < path.size(); ++i) {
        const Vec2d& p0 = path[i == 0 ? 0 : i - 1];
        const Vec2d& p3 = path[std::min(i + 2, path.size() - 1)];
        for (int s = 0; s < kSamplesPerSpan; ++s)
            dense.push_back(catmullRom(p0, path[i], path[i + 1], p3, double(s) / kSamplesPerSpan));
    }
    dense.push_back(path.back());
    return dense;
}

double distanceToPolyline(const std::vector<Vec2d>& line, const Vec2d& p)
{
    double best = std::numeric_limits<double>::max();
    for (std::size_t i = 0; i + 1 < line.size(); ++i) {
        const Vec2d a = line[i], ab = line[i + 1] - a;
        const double lengthSqr = ab.lengthSqr();
        const double t = lengthSqr > 0 ? std::clamp((p - a).dot(ab) / lengthSqr, 0.0, 1.0) : 0.0;
        best = std::min(best, (p - (a + ab * t)).length());
    }
    return best;
}

/// 1 on the path, falling smoothly to 0 at halfWidth; sharper walls keep it
/// near 1 longer (a flat floor) and drop it faster at the rim.
double carveProfile(double distance, const CarveSettings& carve)
{
    const double s = std::clamp(distance / carve.halfWidth, 0.0, 1.0);
    const double shaped = std::pow(s, carve.wallSharpness);
    return 1.0 - shaped * shaped * (3.0 - 2.0 * shaped);
}

} // namespace

void CarveSettings::validate() const
{
    checkFields(*this);
    require(path.size() >= 2, "path", "expected at least two points [x, z]");
    requireNumber("wallRoughness", wallRoughness, 0.0, halfWidth);
}

void TerrainSettings::validate() const
{
    checkFields(*this);
    require(double(cellsX) * cellsZ <= kMaxCells, "cells",
            "expected at most 64 million cells in all, got " + std::to_string(cellsX) + " x " + std::to_string(cellsZ));
}

void SphereSettings::validate() const { checkFields(*this); }

void BoxSettings::validate() const
{
    for (int axis = 0; axis < 3; ++axis) require(max[axis] > min[axis], "", "max must exceed min on every axis");
}

namespace {

/// Evaluates heights with the noise and dense carve paths built once.
class TerrainHeightField {
public:
    explicit TerrainHeightField(const TerrainSettings& options) : mOptions(options), mNoise(options.seed)
    {
        for (const CarveSettings& carve : options.carves) mPaths.push_back(samplePath(carve.path));
    }

    double operator()(double x, double z) const
    {
        const FractalOptions fractal{mOptions.octaves, 2.0, mOptions.roughness};
        const float u = float(x / mOptions.featureSize), v = float(z / mOptions.featureSize);
        // Both styles about [0, 1]; the erosion curve then flattens the low
        // ground into broad valley floors and keeps the crests sharp.
        double unit = mOptions.style == TerrainStyle::Ridged ? double(ridgedMultifractal(mNoise, u, v, fractal))
                                                             : 0.5 * (1.0 + double(fbm(mNoise, u, v, fractal)));
        if (mOptions.erosion > 0.0) unit = std::pow(std::clamp(unit, 0.0, 1.0), 1.0 + 3.0 * mOptions.erosion);
        double height = mOptions.amplitude * unit;
        for (std::size_t i = 0; i < mPaths.size(); ++i) {
            const CarveSettings& carve = mOptions.carves[i];
            double distance = distanceToPolyline(mPaths[i], Vec2d(x, z));
            if (carve.wallRoughness > 0.0) {
                // Offset from the terrain's own noise so the walls do not echo its crests.
                const float u = float(x / carve.halfWidth) + 31.7f, v = float(z / carve.halfWidth) - 12.9f;
                distance += carve.wallRoughness * double(fbm(mNoise, u, v, {3, 2.0, 0.5}));
            }
            const double profile = carveProfile(distance, carve);
            height = carve.floorHeight ? height + (*carve.floorHeight - height) * profile : height - carve.depth * profile;
        }
        return height;
    }

private:
    const TerrainSettings& mOptions;
    GradientNoise mNoise;
    std::vector<std::vector<Vec2d>> mPaths;
};

/// A heightfield over a grid of points, closed into a solid: the surface,
/// four vertical skirts and a bottom `baseThickness` below its lowest point.
/// height(i, k) gives grid point (i, k)'s height, 0 <= i <= cellsX.
template<typename Height>
TriangleMesh heightfieldSolid(double sizeX, double sizeZ, int cellsX, int cellsZ, double baseThickness, const Height& height)
{
    const int nx = cellsX + 1, nz = cellsZ + 1; // grid points per axis
    const auto top = [nz](int i, int k) { return uint32_t(i * nz + k); };

    TriangleMesh mesh;
    mesh.points.resize(std::size_t(nx) * nz);
    double lowest = std::numeric_limits<double>::max();
    for (int i = 0; i < nx; ++i) {
        const double x = -0.5 * sizeX + sizeX * i / cellsX;
        for (int k = 0; k < nz; ++k) {
            const double z = -0.5 * sizeZ + sizeZ * k / cellsZ;
            const double y = height(i, k, x, z);
            lowest = std::min(lowest, y);
            mesh.points[top(i, k)] = Vec3f(float(x), float(y), float(z));
        }
    }
    // Surface: (+z) x (+x) = +y, so (p00, p01, p11) faces up.
    for (int i = 0; i < cellsX; ++i)
        for (int k = 0; k < cellsZ; ++k) {
            mesh.triangles.emplace_back(top(i, k), top(i, k + 1), top(i + 1, k + 1));
            mesh.triangles.emplace_back(top(i, k), top(i + 1, k + 1), top(i + 1, k));
        }

    // Perimeter of the top grid: along the -z edge towards +x, the +x edge
    // towards +z, the +z edge towards -x, the -x edge towards -z.
    std::vector<uint32_t> rim;
    for (int i = 0; i < cellsX; ++i) rim.push_back(top(i, 0));
    for (int k = 0; k < cellsZ; ++k) rim.push_back(top(cellsX, k));
    for (int i = cellsX; i > 0; --i) rim.push_back(top(i, cellsZ));
    for (int k = cellsZ; k > 0; --k) rim.push_back(top(0, k));

    // Skirts down to the bottom plane, then the bottom as a fan from its centre.
    const float bottomY = float(lowest - baseThickness);
    const auto firstBottom = uint32_t(mesh.points.size());
    for (uint32_t r : rim) mesh.points.emplace_back(mesh.points[r][0], bottomY, mesh.points[r][2]);
    const auto centre = uint32_t(mesh.points.size());
    mesh.points.emplace_back(0.0f, bottomY, 0.0f);
    const auto n = uint32_t(rim.size());
    for (uint32_t r = 0; r < n; ++r) {
        const uint32_t a = rim[r], b = rim[(r + 1) % n];
        const uint32_t a0 = firstBottom + r, b0 = firstBottom + (r + 1) % n;
        // Skirt quad (a, b, b0, a0) faces away from the terrain; the bottom faces -y.
        mesh.triangles.emplace_back(a, b, b0);
        mesh.triangles.emplace_back(a, b0, a0);
        mesh.triangles.emplace_back(centre, a0, b0);
    }
    return mesh;
}

} // namespace

double terrainHeight(const TerrainSettings& options, double x, double z)
{
    options.validate();
    return TerrainHeightField(options)(x, z);
}

TriangleMesh makeTerrain(const TerrainSettings& o)
{
    o.validate();
    const TerrainHeightField height(o);
    return heightfieldSolid(o.sizeX, o.sizeZ, o.cellsX, o.cellsZ, o.baseThickness,
                            [&](int, int, double x, double z) { return height(x, z); });
}

void HeightmapSettings::validate() const
{
    require(!path.empty(), "file", "expected an image file");
    checkFields(*this);
}

namespace {

/// Gives every pixel that holds no number the value of its nearest valid
/// pixel (in steps across the image, breadth first: a hole is filled from
/// its rim inwards). Throws FileError when no pixel is valid.
void fillNoData(ImagePlane& image, const std::string& path)
{
    const int w = image.width, h = image.height;
    std::vector<std::size_t> front;
    std::vector<uint8_t> known(image.values.size(), 0);
    for (std::size_t i = 0; i < image.values.size(); ++i)
        if (std::isfinite(image.values[i])) {
            known[i] = 1;
            front.push_back(i);
        }
    if (front.empty()) throw FileError(path, "no pixel holds a number: nothing to fill the holes from");
    while (!front.empty()) {
        std::vector<std::size_t> next;
        for (const std::size_t i : front) {
            const int x = int(i % std::size_t(w)), y = int(i / std::size_t(w));
            for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
                if (x + dx < 0 || x + dx >= w || y + dy < 0 || y + dy >= h) continue;
                const std::size_t n = std::size_t(y + dy) * std::size_t(w) + std::size_t(x + dx);
                if (known[n]) continue;
                known[n] = 1;
                image.values[n] = image.values[i];
                next.push_back(n);
            }
        }
        front = std::move(next);
    }
}

} // namespace

TriangleMesh makeHeightmapTerrain(const HeightmapSettings& o)
{
    o.validate();
    ImagePlane image = readImagePlane(o.path);
    if (image.width < 2 || image.height < 2) throw FileError(o.path, "a heightmap needs at least 2 x 2 pixels");
    const auto where = [&](std::size_t i) {
        return "pixel (" + std::to_string(i % std::size_t(image.width)) + ", " + std::to_string(i / std::size_t(image.width)) +
               ")";
    };
    if (o.fillNoData) {
        fillNoData(image, o.path);
    } else {
        for (std::size_t i = 0; i < image.values.size(); ++i)
            if (!std::isfinite(image.values[i]))
                throw FileError(o.path, where(i) + " holds " + (std::isnan(image.values[i]) ? "NaN" : "an infinite value") +
                                            ", no height (elevation models mark missing data so): set the heightmap's "
                                            "\"fillNoData\": true to fill such pixels from their nearest valid neighbour");
    }
    for (std::size_t i = 0; i < image.values.size(); ++i)
        if (!(std::abs(double(image.values[i]) * o.heightScale) <= HeightmapSettings::kMaxHeight))
            throw FileError(o.path, where(i) + " is " + numberText(double(image.values[i])) + ", a height of " +
                                        numberText(double(image.values[i]) * o.heightScale) + " world units with heightScale " +
                                        numberText(o.heightScale) + " (at most +-" + numberText(HeightmapSettings::kMaxHeight) +
                                        ")");
    const int cellsX = o.cellsX > 0 ? o.cellsX : image.width - 1;
    const int cellsZ = o.cellsZ > 0 ? o.cellsZ : image.height - 1;
    require(double(cellsX) * cellsZ <= TerrainSettings::kMaxCells, "cells", "expected at most 64 million cells in all");
    // Pixel centres span the terrain corner to corner: image x along +x, rows
    // down the image along +z (north up in a map seen from above, -z north).
    const auto pixel = [&](int x, int y) { return double(image.values[std::size_t(y) * image.width + x]); };
    return heightfieldSolid(o.sizeX, o.sizeZ, cellsX, cellsZ, o.baseThickness, [&](int i, int k, double, double) {
        const double px = double(i) / cellsX * (image.width - 1), py = double(k) / cellsZ * (image.height - 1);
        const int x0 = std::min(int(px), image.width - 2), y0 = std::min(int(py), image.height - 2);
        const double fx = px - x0, fy = py - y0;
        const double top = pixel(x0, y0) * (1 - fx) + pixel(x0 + 1, y0) * fx;
        const double bottom = pixel(x0, y0 + 1) * (1 - fx) + pixel(x0 + 1, y0 + 1) * fx;
        return o.heightScale * (top * (1 - fy) + bottom * fy);
    });
}

TriangleMesh makeSphere(const SphereSettings& o)
{
    o.validate();

    // Icosahedron, then each subdivision splits a triangle into four, with
    // shared midpoints so the result stays closed.
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<Vec3d> unit = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                               {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
    for (Vec3d& p : unit) p.normalize();
    std::vector<Vec3ui> faces = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                                 {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (int level = 0; level < o.subdivisions; ++level) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpointOf;
        const auto midpoint = [&](uint32_t a, uint32_t b) {
            const auto key = std::minmax(a, b);
            const auto [it, inserted] = midpointOf.emplace(key, uint32_t(unit.size()));
            if (inserted) unit.push_back((unit[a] + unit[b]).unitSafe());
            return it->second;
        };
        std::vector<Vec3ui> finer;
        finer.reserve(faces.size() * 4);
        for (const Vec3ui& f : faces) {
            const uint32_t ab = midpoint(f[0], f[1]), bc = midpoint(f[1], f[2]), ca = midpoint(f[2], f[0]);
            finer.emplace_back(f[0], ab, ca);
            finer.emplace_back(f[1], bc, ab);
            finer.emplace_back(f[2], ca, bc);
            finer.emplace_back(ab, bc, ca);
        }
        faces = std::move(finer);
    }
    TriangleMesh mesh;
    for (const Vec3d& p : unit) mesh.points.emplace_back(o.center + p * o.radius);
    mesh.triangles = std::move(faces);
    return mesh;
}

TriangleMesh makeBox(const BoxSettings& o)
{
    o.validate();
    TriangleMesh mesh;
    for (int corner = 0; corner < 8; ++corner)
        mesh.points.emplace_back(corner & 1 ? o.max[0] : o.min[0], corner & 2 ? o.max[1] : o.min[1],
                                 corner & 4 ? o.max[2] : o.min[2]);
    // Two triangles per face, counter-clockwise seen from outside.
    mesh.triangles = {{0, 4, 6}, {0, 6, 2},  // -x
                      {1, 3, 7}, {1, 7, 5},  // +x
                      {0, 1, 5}, {0, 5, 4},  // -y
                      {2, 6, 7}, {2, 7, 3},  // +y
                      {0, 2, 3}, {0, 3, 1},  // -z
                      {4, 5, 7}, {4, 7, 6}}; // +z
    return mesh;
}

} // namespace vfield
