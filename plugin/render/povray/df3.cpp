#include <vfield/render/povray/df3.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>

#include <openvdb/tools/Interpolation.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <fstream>

namespace vfield {

namespace {

void putBigEndian16(std::vector<char>& bytes, std::size_t at, uint16_t value)
{
    bytes[at] = char(value >> 8);
    bytes[at + 1] = char(value & 0xff);
}

} // namespace

Df3Placement writeDf3(const openvdb::FloatGrid& density, const std::string& path, int maxResolution)
{
    const openvdb::math::Transform& transform = density.transform();
    const openvdb::Name map = transform.mapType();
    if (map != openvdb::math::UniformScaleMap::mapType() && map != openvdb::math::UniformScaleTranslateMap::mapType())
        throw ValueError("a df3 file needs an axis-aligned density grid with cubic voxels, not a " + map + " transform");

    Df3Placement placement;
    float maxDensity = 0.0f;
    for (auto it = density.cbeginValueOn(); it; ++it) maxDensity = std::max(maxDensity, *it);
    const openvdb::CoordBBox active = density.evalActiveVoxelBoundingBox();
    // One empty cell beyond the active box on every side; cells grow by a whole
    // factor only when an axis would exceed maxResolution.
    const openvdb::Coord extent = active.empty() ? openvdb::Coord(1) : active.dim().offsetBy(2);
    const int factor =
        std::max(1, int(std::ceil(double(std::max({extent.x(), extent.y(), extent.z()})) / std::max(1, maxResolution))));
    const int n[3] = {(extent.x() + factor - 1) / factor, (extent.y() + factor - 1) / factor, (extent.z() + factor - 1) / factor};
    const openvdb::Vec3d first = active.empty() ? openvdb::Vec3d(0.0) : (active.min() - openvdb::Coord(1)).asVec3d();
    // Index-space corner of the sampled cells: cell i covers [first + i f - 1/2, first + (i + 1) f - 1/2)
    // and its sample sits at its centre. POV-Ray puts sample i at i/n of its unit cube, so
    // the cube starts at sample 0 and reaches one cell past the last one (where its
    // interpolation wraps to sample 0: both empty border cells, so it reads zero).
    const openvdb::Vec3d corner = first - openvdb::Vec3d(0.5);
    const openvdb::Vec3d firstSample = corner + openvdb::Vec3d(0.5 * factor);
    placement.worldBounds = BBoxd(transform.indexToWorld(firstSample),
                                  transform.indexToWorld(firstSample + openvdb::Vec3d(n[0], n[1], n[2]) * double(factor)));
    placement.cellSize = transform.voxelSize()[0] * factor;
    placement.densityScale = maxDensity > 0.0f ? maxDensity : 0.0;

    if (n[0] > 65535 || n[1] > 65535 || n[2] > 65535) throw ValueError("a df3 axis holds at most 65535 cells");
    std::vector<char> bytes(6 + 2 * std::size_t(n[0]) * n[1] * n[2]);
    for (int axis = 0; axis < 3; ++axis) putBigEndian16(bytes, 2 * axis, uint16_t(n[axis]));
    const double toValue = maxDensity > 0.0f ? 65535.0 / maxDensity : 0.0;
    tbb::parallel_for(0, n[2], [&](int z) {
        openvdb::FloatGrid::ConstAccessor accessor = density.getConstAccessor();
        for (int y = 0; y < n[1]; ++y)
            for (int x = 0; x < n[0]; ++x) {
                const openvdb::Vec3d centre = corner + (openvdb::Vec3d(x, y, z) + openvdb::Vec3d(0.5)) * double(factor);
                float value = 0.0f;
                if (factor == 1) value = accessor.getValue(openvdb::Coord::round(centre));
                else openvdb::tools::BoxSampler::sample(accessor, centre, value);
                const double quantized = std::round(std::clamp(double(value) * toValue, 0.0, 65535.0));
                putBigEndian16(bytes, 6 + 2 * ((std::size_t(z) * n[1] + y) * n[0] + x), uint16_t(quantized));
            }
    });
    writeFileAtomically(path, [&](const std::string& temporary) {
        std::ofstream out(temporary, std::ios::binary);
        out.write(bytes.data(), std::streamsize(bytes.size()));
        if (!out.flush()) throw FileError(temporary, "cannot write the density file");
    });
    return placement;
}

Df3Volume readDf3(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError(path, "cannot open the density file");
    const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (bytes.size() < 6) throw FileError(path, "too short for a df3 header");
    Df3Volume volume;
    int* sizes[3] = {&volume.nx, &volume.ny, &volume.nz};
    for (int axis = 0; axis < 3; ++axis) *sizes[axis] = bytes[2 * axis] << 8 | bytes[2 * axis + 1];
    const std::size_t count = std::size_t(volume.nx) * volume.ny * volume.nz;
    const std::size_t payload = bytes.size() - 6;
    if (count == 0 || (payload != count && payload != 2 * count))
        throw FileError(path, "holds " + std::to_string(payload) + " bytes of samples for " + std::to_string(volume.nx) + "x" +
                                  std::to_string(volume.ny) + "x" + std::to_string(volume.nz) + " cells");
    volume.values.resize(count);
    for (std::size_t i = 0; i < count; ++i)
        volume.values[i] = payload == count ? uint16_t(bytes[6 + i] * 257) : uint16_t(bytes[6 + 2 * i] << 8 | bytes[7 + 2 * i]);
    return volume;
}

} // namespace vfield
