#include <vfield/scene/memory_estimate.h>

#include <vfield/core/error.h>
#include <vfield/core/image_file.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace vfield {

namespace {

constexpr double kBytesPerTriangle = 120.0;
constexpr double kBytesPerParticle = 192.0;
constexpr double kBytesPerDensityVoxel = 4.0;
constexpr double kBaseBytes = 200.0 * 1024 * 1024;

/// Triangles a mesh source will produce, and the key that sets their number.
std::pair<double, std::string> trianglesOf(const MeshSettings& mesh)
{
    switch (mesh.kind) {
    case MeshSettings::Kind::Terrain: {
        const double x = mesh.terrain.cellsX, z = mesh.terrain.cellsZ;
        return {2.0 * x * z + 6.0 * (x + z), "terrain/cells"}; // the surface, its skirts and its base
    }
    case MeshSettings::Kind::Heightmap: {
        const auto [width, height] = imageResolution(mesh.heightmap.path);
        const double x = mesh.heightmap.cellsX > 0 ? mesh.heightmap.cellsX : std::max(width - 1, 0);
        const double z = mesh.heightmap.cellsZ > 0 ? mesh.heightmap.cellsZ : std::max(height - 1, 0);
        return {2.0 * x * z + 6.0 * (x + z), "heightmap/cells"};
    }
    case MeshSettings::Kind::Sphere:
        return {20.0 * std::pow(4.0, mesh.sphere.subdivisions), "sphere/subdivisions"};
    case MeshSettings::Kind::Box:
        return {12.0, "box"};
    case MeshSettings::Kind::File: {
        std::error_code ec;
        const double size = double(std::filesystem::file_size(mesh.path, ec));
        if (ec) return {0.0, "file"}; // loading will report it
        std::string extension = std::filesystem::path(mesh.path).extension().string();
        std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
        const double bytesPerTriangle = extension == ".stl" ? 50.0 : extension == ".ply" ? 16.0 : 32.0;
        return {size / bytesPerTriangle, "file"};
    }
    }
    return {0.0, ""};
}

std::string countText(double n)
{
    char text[32];
    std::snprintf(text, sizeof text, "%.0f", n);
    return text;
}

} // namespace

std::string memoryText(double bytes)
{
    char text[32];
    if (bytes >= 1024.0 * 1024 * 1024) std::snprintf(text, sizeof text, "%.1f GiB", bytes / (1024.0 * 1024 * 1024));
    else std::snprintf(text, sizeof text, "%.0f MiB", bytes / (1024.0 * 1024));
    return text;
}

MemoryEstimate estimateSimulationMemory(const Scene& scene)
{
    MemoryEstimate estimate;
    estimate.bytes = kBaseBytes;
    const SimulationSettings& setup = scene.simulation;
    for (std::size_t i = 0; i < setup.objects.size(); ++i) {
        const auto [triangles, key] = trianglesOf(setup.objects[i].mesh);
        MemoryEstimate::Part part{"/objects/" + std::to_string(i) + "/mesh/" + key, countText(triangles) + " triangles",
                                  triangles * kBytesPerTriangle};
        estimate.bytes += part.bytes;
        estimate.parts.push_back(part);
    }
    for (std::size_t c = 0; c < setup.clouds.size(); ++c) {
        const CloudSettings& cloud = setup.clouds[c];
        // The density covers the particles' kernels, at most the cloud's box (as it starts; it moves and spreads).
        const double voxel = scene.volume.voxelSize, kernel = 2.0 * scene.volume.kernelRadius / voxel + 1.0;
        const double box = 8.0 * cloud.radii[0] * cloud.radii[1] * cloud.radii[2] / (voxel * voxel * voxel);
        const double voxels = std::min(box, double(cloud.count) * kernel * kernel * kernel);
        MemoryEstimate::Part part{"/clouds/" + std::to_string(c) + "/count", countText(double(cloud.count)) + " particles",
                                  double(cloud.count) * kBytesPerParticle + voxels * kBytesPerDensityVoxel};
        estimate.bytes += part.bytes;
        estimate.parts.push_back(part);
    }
    return estimate;
}

MemoryEstimate estimateMeshFileMemory(const std::string& path)
{
    MeshSettings source;
    source.kind = MeshSettings::Kind::File;
    source.path = path;
    const double triangles = trianglesOf(source).first;
    MemoryEstimate estimate;
    estimate.parts.push_back({"", countText(triangles) + " triangles (by the file's size)", triangles * kBytesPerTriangle});
    estimate.bytes = kBaseBytes + estimate.parts.back().bytes;
    return estimate;
}

std::optional<double> availableMemory()
{
    std::ifstream in("/proc/meminfo");
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream fields(line);
        std::string name;
        double kib = 0.0;
        if (fields >> name >> kib && name == "MemAvailable:") return kib * 1024.0;
    }
    return std::nullopt;
}

void requireMemoryWithin(const MemoryEstimate& estimate, double limitBytes, const std::string& limitName,
                         const std::string& subject)
{
    if (estimate.bytes <= limitBytes) return;
    const auto largest = std::max_element(estimate.parts.begin(), estimate.parts.end(),
                                          [](const auto& a, const auto& b) { return a.bytes < b.bytes; });
    const std::string detail = subject + " needs about " + memoryText(estimate.bytes) + " of memory, more than " + limitName +
                               " (" + memoryText(limitBytes) + ")";
    if (largest == estimate.parts.end()) throw ValueError(detail);
    throw OptionError(largest->key, detail + "; " + largest->what + " here take " + memoryText(largest->bytes) +
                                        " (raise the limit with --max-memory)");
}

} // namespace vfield
