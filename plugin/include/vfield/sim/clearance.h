#pragma once
/// @file clearance.h
/// Measured truth about collisions: signed distances (world units, negative
/// inside) from points to every static object's mesh, from OpenVDB level sets
/// (tools::meshToSignedDistanceField, meshToLevelSet with an asymmetric band). Used per frame on particles and on dynamic
/// objects' vertices; penetrations are counted, never hidden.

#include <vfield/sim/simulator.h>

#include <openvdb/openvdb.h>

#include <string>
#include <vector>

namespace vfield {

struct ClearanceStats {
    double minimum = 0.0;      ///< smallest signed distance, world units
    double percentile1 = 0.0;  ///< 1st percentile of the signed distances
    uint64_t penetrations = 0; ///< points at negative distance
    uint64_t samples = 0;      ///< points measured (0: nothing to measure)
};

class ClearanceProbe {
public:
    /// Builds a level set per static object: voxel size half its field's
    /// finest leaf (or 1/256 of its size without a field), a band reaching 10%
    /// of its field's root side outside (beyond it distances read as the band's
    /// width) and 3 voxels inside. Open meshes, whose inside is undefined, are
    /// measured but reported in warnings().
    explicit ClearanceProbe(const Simulator& simulator);

    /// Signed distance from a world point to the nearest static mesh.
    double distance(const Vec3d& world) const;
    ClearanceStats measure(const std::vector<Vec3d>& worldPoints) const;
    ClearanceStats measureParticles(const ParticleSet& particles) const;
    /// The world positions of a dynamic object's vertices at its current pose.
    static std::vector<Vec3d> vertices(const SimObject& object, const Transform& pose);

    const std::vector<std::string>& warnings() const { return mWarnings; }
    bool empty() const { return mLevelSets.empty(); }

private:
    struct LevelSet {
        openvdb::FloatGrid::Ptr grid; ///< object space
        Transform pose;
    };
    std::vector<LevelSet> mLevelSets;
    std::vector<std::string> mWarnings;
};

} // namespace vfield
