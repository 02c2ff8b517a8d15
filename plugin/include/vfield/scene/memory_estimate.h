#pragma once
/// @file memory_estimate.h
/// What simulating a scene will hold in memory, estimated from the scene file
/// alone, before anything is loaded or built: so that a scene too large for
/// the machine is refused at once, naming the key that makes it large,
/// instead of exhausting memory minutes later with nothing written.
///
/// The costs are fitted to simulations' peak resident set sizes: about 120
/// bytes per mesh triangle (the mesh, its octree while it is built, the
/// voxelized field, the clearance level set; alike over tens of millions of
/// triangles), 192 per particle (positions and velocities, the particle and
/// density grids, the saved state), 4 per density voxel the clouds' initial
/// boxes cover at most, and 200 MiB for the libraries and buffers. Mesh
/// files count as triangles by their size (an OBJ or OFF line per vertex and
/// face, about 32 bytes per triangle; binary PLY 16; STL 50); `tessellate`
/// is not counted.

#include <vfield/scene/scene.h>

#include <optional>
#include <string>
#include <vector>

namespace vfield {

struct MemoryEstimate {
    struct Part {
        std::string key;  ///< where in the scene file, a JSON pointer, e.g. "/objects/0/mesh/terrain/cells"
        std::string what; ///< e.g. "128000000 triangles"
        double bytes = 0.0;
    };
    double bytes = 0.0;      ///< the whole simulation
    std::vector<Part> parts; ///< objects and clouds, in scene order
};

MemoryEstimate estimateSimulationMemory(const Scene& scene);

/// Loading a mesh file and building its field (probe, bake-field,
/// field-slice): the same costs, the file counted by its size.
MemoryEstimate estimateMeshFileMemory(const std::string& path);

/// The memory the system could give a new process without swapping
/// (MemAvailable in /proc/meminfo), bytes; nullopt where it cannot be read.
std::optional<double> availableMemory();

/// Throws OptionError on the largest part's key when the estimate exceeds
/// limitBytes, with both figures in the message ("<subject> needs about ...").
void requireMemoryWithin(const MemoryEstimate& estimate, double limitBytes, const std::string& limitName,
                         const std::string& subject = "the scene");

/// "15.6 GiB", "512 MiB".
std::string memoryText(double bytes);

} // namespace vfield
