#pragma once
/// @file volume_detail.h
/// How the density is shaped beyond the particles' kernels: noise detail
/// (DetailSettings) and condensation (CondensationSettings), as a scene's
/// volume.detail and volume.condensation declare them.
///
/// With detail, the density is resampled on a finer grid and shaped by
/// fractal noise drawn at each point's interpolated rest position (where its
/// particles were emitted), so the detail is attached to the material: it
/// travels and deforms with the cloud instead of swimming through it. With
/// dual rest (ParticleSet::rest2), the noise is drawn at both rest positions
/// and blended by rest2Weight, normalized so that the blend keeps the
/// noise's contrast: the detail stretches with the material no more than one
/// rest period's motion.

#include <vfield/core/fields.h>

#include <cstdint>

namespace vfield {

/// How the detail's noise shapes the density.
enum class DetailStyle {
    /// Soft, eroded edges:
    ///   density' = density x max(0, 1 + amplitude g / 2) x smoothstep(0, 1, density / edgeSoftness x (1 + amplitude g))
    /// with g = fbm(frequency x rest) in about [-1, 1]: deep inside, the noise
    /// billows the density by up to half the amplitude; at the edges (density
    /// near edgeSoftness and below) it decides what is kept, so edges turn to
    /// wisps. The edge stays as soft as the particles' kernel, and a ray
    /// grazing the cloud averages the noise out: its outlines measure little
    /// rougher than a disk's 1 (vfield silhouette), where real clouds measure 1.33.
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
    /// on it, and the opacity's outline stays nearly as smooth as a disk's.
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
    /// rough down to the finest octave, near real clouds' roughness.
    /// Beyond the particles, the rest positions are carried off the splat's
    /// surface along its normals (as offsets from the world position), so
    /// the lumps move with the cloud.
    Displaced
};
inline constexpr EnumName<DetailStyle> kDetailStyleNames[] = {
    {DetailStyle::Erode, "erode"}, {DetailStyle::Billows, "billows"}, {DetailStyle::Displaced, "displaced"}};
constexpr const auto& enumNames(DetailStyle) { return kDetailStyleNames; }

/// Noise detail finer than the particles, eroding, billowing or displacing the cloud (DetailStyle).
struct DetailSettings {
    double voxelSize = 0.0;
    double frequency = 0.3;
    int octaves = 4;
    double gain = 0.5;
    double amplitude = 0.8;
    double edgeSoftness = 0.0;
    DetailStyle style = DetailStyle::Erode;
    uint64_t seed = 1;

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
///   share = smoothstep(0, 1, 1 - (level - y) / depth)
/// with level the peak. With a lift, the level is instead `lift` above where
/// the particle started (ParticleSet::origin), its lifting condensation
/// level: moist air is clear until it rises to it and clears again as it
/// sinks back, so a cloud stands where air rises (a cap cloud over a crest)
/// while the air flows through it.
struct CondensationSettings {
    double depth = 0.0;
    double lift = 0.0;

    bool enabled() const { return depth > 0.0; }
    void validate() const;
    /// A particle's share of its density at height y, having reached `peak`
    /// and started at `origin` (1 when off).
    float share(float y, float peak, float origin) const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("depth", self.depth)
                  .range(0, 1e9)
                  .unit("world units")
                  .doc("how far a particle sinks below its condensation level before its density is gone "
                       "(smoothly); 0: off"));
        visit(field("lift", self.lift)
                  .range(0, 1e9)
                  .unit("world units")
                  .doc("its lifting condensation level: a particle's water condenses as it rises to this far above "
                       "where it started and evaporates as it sinks back below, so a cloud forms where air rises and "
                       "vanishes where it descends; 0: the level is the highest point it reached (it is born condensed "
                       "and only evaporates as it sinks)"));
    }
};

} // namespace vfield
