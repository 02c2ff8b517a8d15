#pragma once
/// @file clearance.h
/// Measured truth about collisions: signed distances (world units, negative
/// inside) to every object's mesh, from OpenVDB level sets (MeshDistance).
/// Per frame: the particles against every object (static ones and dynamic
/// ones where they are), and every dynamic object's mesh against every other
/// object's, surface against surface. Penetrations are counted, never hidden.

#include <vfield/sim/simulator.h>

#include <memory>
#include <string>
#include <vector>

namespace vfield {

struct ClearanceStats {
    double minimum = 0.0;     ///< smallest signed distance, world units
    double percentile1 = 0.0; ///< 1st percentile of the signed distances
    /// Mean signed distance, each read at most as far as the level sets reach
    /// (beyond it, as that reach: a lower bound of the mean)
    double mean = 0.0;
    uint64_t penetrations = 0; ///< points at negative distance
    uint64_t samples = 0;      ///< points measured (0: nothing to measure)

    /// Takes in another set's measures, as if measured together: the
    /// smaller minimum, the mean of all, penetrations and samples summed. The
    /// 1st percentile of the union is not known from the two: the smaller of
    /// the two is kept, a lower bound of it.
    void add(const ClearanceStats& other);
};

/// The clearance between two objects' meshes at one moment.
struct PairClearance {
    std::string first, second; ///< object names; first is dynamic
    /// Smallest signed distance between the two surfaces, world units:
    /// negative where they overlap. Exact to within the finer level set's
    /// voxel up to half the wider of the two level sets' exterior bands;
    /// surfaces farther apart read as that half band (a lower bound).
    double minimum = 0.0;
    bool exact = true; ///< false: minimum is that lower bound
};

class ClearanceProbe {
public:
    /// Builds a level set per static object with a closed mesh: voxel size
    /// half its field's finest leaf (or 1/256 of its size without a field), a
    /// band reaching 10% of its field's root side outside (beyond it distances
    /// read as the band's width) and 3 voxels inside. Dynamic objects bring
    /// their own (SimObject::distance). Open meshes, whose inside is
    /// undefined, are measured but reported in warnings(). Reads the
    /// simulator's poses when measuring: keep it alive.
    explicit ClearanceProbe(const Simulator& simulator);

    /// Signed distance from a world point to the nearest mesh, as now placed.
    double distance(const Vec3d& world) const;
    ClearanceStats measure(const std::vector<Vec3d>& worldPoints) const;
    ClearanceStats measureParticles() const;
    /// Every dynamic object against every other object, mesh to mesh: the
    /// first's triangles, sampled a voxel apart, in the second's level set,
    /// and the second's triangles near it in the first's.
    std::vector<PairClearance> measureObjects() const;

    const std::vector<std::string>& warnings() const { return mWarnings; }
    bool empty() const { return mSurfaces.empty(); }

private:
    struct Surface {
        std::size_t object;
        std::shared_ptr<const MeshDistance> distance;
    };
    /// One direction of a pair's measure: exact where value < atLeast (half
    /// the level set's band, world units); else the surfaces are at least that far apart.
    struct Reading {
        double value, atLeast;
        bool exact() const { return value < atLeast; }
    };
    Reading surfaceToSurface(std::size_t from, const Surface& to) const;

    const Simulator& mSimulator;
    std::vector<Surface> mSurfaces;
    std::vector<std::string> mWarnings;
};

} // namespace vfield
