#pragma once
/// @file particles.h
/// Particle state, structure of arrays, world space. The simulator re-sorts
/// the particles into spatial order every few frames (sortSpatially); `id`
/// names a particle.

#include <vfield/core/math.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vfield {

/// Keeps the values whose flag is set, in order, `stride` consecutive values
/// a flag (an attribute with several values a particle). An empty vector (an
/// optional attribute not kept) stays empty.
template<typename T>
void keepFlagged(std::vector<T>& values, const std::vector<uint8_t>& alive, std::size_t stride = 1)
{
    if (values.empty()) return;
    std::size_t kept = 0;
    for (std::size_t i = 0; i < alive.size(); ++i)
        if (alive[i]) std::copy_n(values.begin() + i * stride, stride, values.begin() + kept++ * stride);
    values.resize(kept * stride);
}

struct ParticleSet {
    std::vector<Vec3f> position; ///< world units
    std::vector<Vec3f> velocity; ///< world units / s
    /// Where the particle was emitted, or where it stood when its rest was
    /// last reset (world units): the material coordinate that detail is drawn
    /// at, so that detail travels with the cloud.
    std::vector<Vec3f> rest;
    /// Dual rest (SolverSettings::restPeriod): a second rest position,
    /// reset half a period after `rest`; empty with a single rest.
    std::vector<Vec3f> rest2;
    /// How much of the detail comes from rest2 (0..1): 0 whenever rest2 is
    /// reset, 1 whenever rest is, so no reset shows. 0 with a single rest.
    float rest2Weight = 0.0f;
    /// The highest the particle has been at a frame's end (world y): how far
    /// it has sunk since is what evaporates it (VolumeSettings::condensation).
    /// The simulator keeps one per particle; may be empty in sets made elsewhere.
    std::vector<float> peak;
    /// The height where the particle started (world y): where it was emitted,
    /// or where the preroll left it. How far it has risen above it is what
    /// condenses it when condensation has a lift. Kept like `peak`.
    std::vector<float> origin;
    /// Emitted particles' lives (CloudEmissionSettings), seconds from the
    /// first frame: born at `birth`, gone at `death` (infinity: never); and
    /// the share of its density a particle has as it fades in after its
    /// birth and out before its death (1 between), as of the frame's end.
    /// Empty unless a cloud of the scene emits over time.
    std::vector<float> birth, death, fade;
    std::vector<uint32_t> id;    ///< unique for the whole sequence
    std::vector<float> radius;   ///< world units (pscale)
    std::vector<uint16_t> cloud; ///< index of the cloud it came from

    std::size_t size() const { return position.size(); }
    void reserve(std::size_t n);
    /// Keeps the particles whose flag is set, in order.
    void keep(const std::vector<uint8_t>& alive);
    /// Reorders the particles along a Morton curve over the box (1024 cells a
    /// side; outside it, clamped to its faces), ties in their current order:
    /// particles near in space become near in memory, so field lookups and
    /// splats read memory in order rather than at random.
    void sortSpatially(const BBoxd& box);
    /// Reorders the particles: the i-th becomes the one that was order[i]th.
    void reorder(const std::vector<uint32_t>& order);
    /// Puts the particles in id order: one order for the same particles, however they came.
    void sortById();
    /// Appends other's particles (rest2Weight stays this set's).
    void append(const ParticleSet& other);
};

} // namespace vfield
