#pragma once
/// @file density_splat.h
/// ParticleSet (world space) -> FloatGrid `density` and Vec3SGrid `vel`
/// (world space, the names Houdini and Blender expect).
///
/// With detail (volume_detail.h), the density is resampled on a finer grid
/// and shaped by noise that moves with the cloud.
///
/// Each particle spreads densityPerParticle over a smooth kernel: its
/// trilinear (cloud-in-cell) weights on the eight voxels around it, blurred by
/// passes of OpenVDB's 3-voxel mean filter, as many as bring the kernel's
/// spread closest to that of W(r) = 315 / (64 pi R^3) (1 - r^2/R^2)^3 of radius
/// R = kernelRadius (per-axis variance R^2 / 11), at least one. The kernel
/// integrates to 1, so the grid's integral is particles x densityPerParticle;
/// it is four voxels wide or more and moves continuously with the particle,
/// so nothing pops. Depositing eight weights a particle and blurring the grid
/// once costs far less than spreading every particle over its whole kernel.
/// `vel` is the kernel-weighted mean velocity. The deposit's sums are taken
/// in fixed point, so the grids are the same, bit for bit, for the same
/// particles in any order and for any number of threads: one run's, and
/// the merge of its shards'.

#include <vfield/core/fields.h>
#include <vfield/core/vdb_trees.h>
#include <vfield/sim/particles.h>
#include <vfield/volume/particle_grid.h>
#include <vfield/volume/volume_detail.h>

namespace vfield {

/// How a grid of density.####.vdb is stored.
enum class GridPrecision {
    Half, ///< 16-bit floats (OpenVDB's saveFloatAsHalf): 1 part in 2048, half the bytes
    Float ///< 32-bit floats
};
inline constexpr EnumName<GridPrecision> kGridPrecisionNames[] = {{GridPrecision::Half, "half"}, {GridPrecision::Float, "float"}};
constexpr const auto& enumNames(GridPrecision) { return kGridPrecisionNames; }

struct VolumeSettings {
    static constexpr double kMaxKernelVoxels = 32.0; ///< the kernel's radius spans at most this many voxels
    /// A displaced surface (DetailStyle::Displaced) moves over at most this
    /// many voxels: its distance to the splat's surface is grown over them, a layer a voxel.
    static constexpr double kMaxDisplacementVoxels = 64.0;

    double voxelSize = 0.0;
    double kernelRadius = 0.0; ///< resolved to at least one voxel
    double densityPerParticle = 1.0;
    DetailSettings detail;
    CondensationSettings condensation;
    /// What it leaves out has an optical depth of at most extinction x cutoff
    /// x peak per unit.
    double cutoff = 0.1;
    GridPrecision densityPrecision = GridPrecision::Half;
    GridPrecision velocityPrecision = GridPrecision::Half;
    ParticlePrecision particlePrecision = ParticlePrecision::Compact;

    /// Throws OptionError naming the first option out of range, a kernel
    /// spanning more than kMaxKernelVoxels voxels, or a displaced detail
    /// moving over more than kMaxDisplacementVoxels.
    void validate() const;
    /// These options with the defaults filled in for particles of the given
    /// mean radius: the only place the defaults are computed. Unchecked: call
    /// validate() on the result.
    VolumeSettings resolved(double meanParticleRadius) const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("voxelSize", self.voxelSize)
                  .range(0, 1e9)
                  .unit("world units")
                  .defaultText("mean particle radius")
                  .doc("density voxel size; 0: the default"));
        visit(field("kernelRadius", self.kernelRadius)
                  .range(0, 1e9)
                  .unit("world units")
                  .defaultText("2 x mean particle radius")
                  .doc("spread of the kernel: that of the smooth kernel (1 - r^2/R^2)^3 of this radius, at most 32 voxels; 0: "
                       "the default"));
        visit(field("densityPerParticle", self.densityPerParticle)
                  .range(0, 1e12)
                  .doc("what one particle adds to the density's integral (extinction is density x sigma)"));
        visit(field("detail", self.detail).doc("noise detail finer than the particles, moving with the cloud"));
        visit(field("condensation", self.condensation)
                  .doc("clouds that evaporate as their air sinks from the highest point it reached; off unless depth is set"));
        visit(field("cutoff", self.cutoff)
                  .range(0, 1)
                  .doc("voxels below this fraction of one lone particle's peak density are left out of the grid: the "
                       "kernels' faint fringe, where a dense cloud has many of its voxels; those on the faces of the grid's "
                       "active box stay, so its bounds do not "
                       "move; 0 keeps every voxel"));
        visit(field("densityPrecision", self.densityPrecision)
                  .doc("how density.####.vdb stores `density`: half, 16-bit floats (1 part in 2048, half the bytes); "
                       "float, 32-bit"));
        visit(field("velocityPrecision", self.velocityPrecision)
                  .doc("how density.####.vdb stores `vel` (defined where the density is): half or float, as "
                       "densityPrecision"));
        visit(field("particlePrecision", self.particlePrecision)
                  .doc("how particles.####.vdb stores its attributes: compact, OpenVDB's point codecs (P in 16 bits "
                       "within its voxel, v, rest and rest2 as 16-bit floats, pscale in 8 bits for radii up to 1 and once per "
                       "leaf where shared); "
                       "full, 32-bit floats"));
    }
};

struct DensityGrids {
    openvdb::FloatGrid::Ptr density;
    openvdb::Vec3SGrid::Ptr velocity;
};

/// Where a splat's time went (wall clock, seconds).
struct SplatSeconds {
    double splat = 0.0;  ///< the deposit, the blur and the grids' values
    double detail = 0.0; ///< the noise detail, the cutoff and the velocity's trim
};
/// Splats with options.resolved(mean radius of the particles), the grids set
/// to be written at options' precisions; particles in
/// spatial order (ParticleSet::sortSpatially) splat about ten times faster
/// than in random order. Throws
/// OptionError if the voxel size would make an absurd kernel. particles.rest
/// may be empty: positions then stand in for it; rest2 is used when it has a
/// position for every particle, peak when it has a height for every
/// particle (otherwise each counts as at its peak). With detail, `density` is
/// the detailed grid (detail.voxelSize) and `vel` stays at the splat's voxel size.
DensityGrids splatParticles(const ParticleSet& particles, const VolumeSettings& options, SplatSeconds* seconds = nullptr);

} // namespace vfield
