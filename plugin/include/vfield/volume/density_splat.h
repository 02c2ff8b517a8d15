#pragma once
/// @file density_splat.h
/// ParticleSet (world space) -> FloatGrid `density` and Vec3SGrid `vel`
/// (world space, the names Houdini and Blender expect).
///
/// With detail (VolumeDetail), the density is resampled on a finer grid and
/// shaped by fractal noise drawn at each point's interpolated rest position
/// (where its particles were emitted), so the detail is attached to the
/// material: it travels and deforms with the cloud instead of swimming through it.
/// With dual rest (ParticleSet::rest2), the noise is drawn at both rest
/// positions and blended by rest2Weight, normalized so that the blend keeps
/// the noise's contrast: the detail stretches with the material no more than
/// one rest period's motion.
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
/// `vel` is the kernel-weighted mean velocity. Sums run in a fixed order
/// whatever the thread count, so grids are identical for any number of threads.

#include <vfield/core/fields.h>
#include <vfield/sim/particles.h>
#include <vfield/volume/particle_grid.h>

#include <openvdb/openvdb.h>

namespace vfield {

/// How the detail's noise shapes the density.
enum class DetailStyle {
    /// Soft, eroded edges:
    ///   density' = density x max(0, 1 + amplitude g / 2) x smoothstep(0, 1, density / edgeSoftness x (1 + amplitude g))
    /// with g = fbm(frequency x rest) in about [-1, 1]: deep inside, the noise
    /// billows the density by up to half the amplitude; at the edges (density
    /// near edgeSoftness and below) it decides what is kept, so edges turn to
    /// wisps. The edge stays as soft as the particles' kernel, and a ray
    /// grazing the cloud averages the noise out: the main job's outlines
    /// measured 1.01 to 1.15 (vfield silhouette), where real clouds measure 1.33.
    Erode,
    /// A cumulus's crisp, cauliflower surface: the cloud is what lies inside
    /// the surface x = density / edgeSoftness + amplitude b = 1/2, with b = 2
    /// billow(frequency x rest) - 1 (rounded lumps, creases between them), and
    /// its edge jumps to half edgeSoftness (fading only in the kernels'
    /// faintest fringe, so that it ends where the splat does):
    ///   density' = max(density, min(edgeSoftness / 2, 8 density)) x smoothstep(0.45, 0.55, x)
    /// so the outline a viewer sees is the surface's, lumps on lumps. The
    /// surface moves by amplitude b over the density's gradient, a voxel or
    /// two where the kernels end: the lumps lie inside the outline more than
    /// on it (a cumulus's opacity measured 1.06).
    Billows,
    /// Lumps on lumps at every scale, octave i's standing out up to about
    /// amplitude x (2 gain)^i times their width (alike at every scale at gain
    /// 0.5, relatively more at the finer ones above it): the cloud is what
    /// lies inside the splat's surface (where its density is edgeSoftness /
    /// 2) moved out along its normal by
    ///   h = amplitude x (1 + gain + gain^2 + ...) / frequency x (b - 0.44)
    /// world units, with b = billow(frequency x rest) in [0, 1] and 0.44 its
    /// mean, so the cloud keeps its size: lumps stand out where b is high,
    /// creases cut in where it is low. The coarse octaves, those with a
    /// lattice cell of at least four of the splat's voxels, are summed on the
    /// splat's voxels and read trilinearly between them; the others on the
    /// detail's, only near the surface the coarse ones moved; each part is a
    /// billow of its own octaves, moving the surface by its octaves' share of
    /// the sum 1 + gain + gain^2 + .... Inside, the density is the splat's but
    /// at least edgeSoftness, so that a lump as small as the finest octave
    /// still shows; the surface fades over one fine voxel. The outline is
    /// rough down to the finest octave (a cumulus's opacity measured 1.28).
    /// Beyond the particles, the rest positions are carried off the splat's
    /// surface along its normals (as offsets from the world position), so
    /// the lumps move with the cloud.
    Displaced
};
inline constexpr EnumName<DetailStyle> kDetailStyleNames[] = {
    {DetailStyle::Erode, "erode"}, {DetailStyle::Billows, "billows"}, {DetailStyle::Displaced, "displaced"}};
constexpr const auto& enumNames(DetailStyle) { return kDetailStyleNames; }

/// Noise detail finer than the particles, eroding, billowing or displacing the cloud (DetailStyle).
struct VolumeDetail {
    double voxelSize =
        0.0; ///< detail voxel size, world units (0..1e9); 0: no detail. Rounded so that it divides the splat's voxel
    double frequency = 0.3; ///< of the coarsest octave, 1 / world units of rest position (1e-9..1e9)
    int octaves = 4;        ///< (1..10)
    /// Amplitude ratio of successive octaves (0.1..0.95): 0.5 is a smooth
    /// noise whose outlines measure about 1; g makes outlines of box-counting
    /// dimension about 2 + log2(g) over the octaves' scales (0.7: 1.49).
    double gain = 0.5;
    double amplitude = 0.8;    ///< (0..4)
    double edgeSoftness = 0.0; ///< density units (0..1e12); 0: the peak density of one lone particle
    DetailStyle style = DetailStyle::Erode;
    uint64_t seed = 1; ///< noise seed

    bool enabled() const { return voxelSize > 0.0; }
    void validate() const;
    /// The world units a Displaced surface moves over, in and out:
    /// amplitude x (1 + gain + ... + gain^(octaves - 1)) / frequency.
    double displacementRange() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("voxelSize", self.voxelSize)
                  .range(0, 1e9)
                  .unit("world units")
                  .doc("the detail's voxel, rounded so that it divides volume.voxelSize; 0: no detail"));
        visit(field("frequency", self.frequency)
                  .range(1e-9, 1e9)
                  .unit("1/world units")
                  .doc("of the coarsest octave, over rest positions"));
        visit(field("octaves", self.octaves).range(1, 10).doc("noise octaves"));
        visit(field("gain", self.gain)
                  .range(0.1, 0.95)
                  .doc("amplitude ratio of successive octaves: 0.5 is smooth; larger is rougher, outlines of fractal "
                       "dimension about 2 + log2(gain) over the octaves' scales (real clouds: 1.33 to 1.35, gain 0.63)"));
        visit(field("amplitude", self.amplitude)
                  .range(0, 4)
                  .doc("how strongly the noise billows the inside and erodes the edges; displaced: how far the coarsest "
                       "octave's lumps stand out per unit of their width"));
        visit(field("edgeSoftness", self.edgeSoftness)
                  .range(0, 1e12)
                  .unit("density units")
                  .defaultText("one lone particle's peak density")
                  .doc("density over which the edges are eroded; larger erodes deeper; 0: the default"));
        visit(field("style", self.style)
                  .doc("erode: soft edges eroded into wisps; billows: a crisp cauliflower surface, lumps on lumps (billow "
                       "noise), the edge jumping to half edgeSoftness; displaced: the splat's surface moved in and out "
                       "by billow noise over a range of amplitude x (1 + gain + gain^2 + ...) / frequency world units, "
                       "lumps on lumps at every octave, the outline rough down to the finest"));
        visit(field("seed", self.seed).doc("noise seed"));
    }
};

/// Clouds that dissolve as their air sinks: a parcel of cloud holds the
/// droplets it condensed at the highest (coldest) point it reached, and
/// sinking warms it and evaporates them. Each particle deposits its full
/// share of the density while at its peak height (ParticleSet::peak) and
/// smoothly less as it sinks below it, none `depth` under it, so a cloud
/// pouring over a ridge and down its lee slope thins into wisps (where the
/// detail erodes the thinned edges) and vanishes, as a tablecloth cloud does.
///   share = smoothstep(0, 1, 1 - (peak - y) / depth)
struct Condensation {
    double depth = 0.0; ///< world units (0..1e9) a particle sinks below its peak before its density is gone; 0: off

    bool enabled() const { return depth > 0.0; }
    void validate() const;
    /// A particle's share of its density at height y after a peak at `peak` (1 when off).
    float share(float y, float peak) const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("depth", self.depth)
                  .range(0, 1e9)
                  .unit("world units")
                  .doc("how far a particle sinks below the highest point it reached before its density is gone "
                       "(smoothly); 0: off"));
    }
};

/// How a grid of density.####.vdb is stored.
enum class GridPrecision {
    Half, ///< 16-bit floats (OpenVDB's saveFloatAsHalf): 1 part in 2048, half the bytes
    Float ///< 32-bit floats
};
inline constexpr EnumName<GridPrecision> kGridPrecisionNames[] = {{GridPrecision::Half, "half"}, {GridPrecision::Float, "float"}};
constexpr const auto& enumNames(GridPrecision) { return kGridPrecisionNames; }

struct VolumeOptions {
    static constexpr double kMaxKernelVoxels = 32.0; ///< the kernel's radius spans at most this many voxels
    /// A displaced surface (DetailStyle::Displaced) moves over at most this
    /// many voxels: its distance to the splat's surface is grown over them, a layer a voxel.
    static constexpr double kMaxDisplacementVoxels = 64.0;

    double voxelSize = 0.0;    ///< world units (0..1e9); 0: the particles' mean radius
    double kernelRadius = 0.0; ///< world units (0..1e9): the spread of the smooth kernel matched; 0: 2 x the particles' mean
                               ///< radius; at least one voxel
    double densityPerParticle = 1.0; ///< density integral of one particle (0..1e12; extinction is density x sigma)
    VolumeDetail detail;
    Condensation condensation;
    /// Voxels below this fraction of one lone particle's peak density are
    /// left out (0..1): the kernels' faint fringe, whose optical depth is at
    /// most extinction x cutoff x peak per unit; 0 keeps every voxel.
    double cutoff = 0.1;
    GridPrecision densityPrecision = GridPrecision::Half;             ///< of density.####.vdb's `density`
    GridPrecision velocityPrecision = GridPrecision::Half;            ///< of density.####.vdb's `vel`
    ParticlePrecision particlePrecision = ParticlePrecision::Compact; ///< of particles.####.vdb

    /// Throws OptionError naming the first option out of range, a kernel
    /// spanning more than kMaxKernelVoxels voxels, or a displaced detail
    /// moving over more than kMaxDisplacementVoxels.
    void validate() const;
    /// These options with the defaults filled in for particles of the given
    /// mean radius: the only place the defaults are computed. Unchecked: call
    /// validate() on the result.
    VolumeOptions resolved(double meanParticleRadius) const;

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
                       "kernels' faint fringe (two fifths of the main job's voxels, each less dense than a tenth of a lone "
                       "particle's centre); those on the faces of the grid's active box stay, so its bounds do not "
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
DensityGrids splatParticles(const ParticleSet& particles, const VolumeOptions& options, SplatSeconds* seconds = nullptr);

} // namespace vfield
