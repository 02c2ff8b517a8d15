#pragma once
/// @file turbulence.h
/// Turbulence: swirls at several sizes that stir a cloud as eddies in the
/// air do, so that billows grow, roll and travel with the flow instead of
/// being drawn on a cloud that moves as one block. The acceleration is curl
/// noise (Bridson, Hourihan and Nordenstam, "Curl-noise for procedural fluid
/// flow", SIGGRAPH 2007): one octave after another, the curl of the vector
/// potential n grad m of two gradient noises n and m, which is grad n x grad m,
/// so it is divergence-free by construction: it stirs without sources or
/// sinks, and a cloud it moves neither gathers into clumps nor tears holes.
/// Houdini's POP Curl Noise and Blender's turbulence force field are its
/// relatives.
///
/// It acts on particles and dynamic objects like the uniform fields, as an
/// acceleration alike for every mass, in world space; the objects' repulsive
/// fields and contact keep everything it pushes out of the meshes.

#include <vfield/core/animation.h>
#include <vfield/core/fields.h>
#include <vfield/core/math.h>
#include <vfield/core/noise.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace vfield {

struct TurbulenceSettings {
    std::string name = "turbulence";
    double strength = 1.0;
    double size = 10.0; ///< the first octave's wavelength
    static constexpr int kMaxOctaves = 8;
    int octaves = 3;
    double roughness = 0.5;
    double evolution = 0.2;
    uint64_t seed = 1;                ///< mixed with nothing else
    std::vector<std::string> affects; ///< empty: everything that moves
    Animation animation;

    /// Whether it acts on the object or cloud of this name.
    bool acts(const std::string& name) const;
    /// Throws OptionError naming the first option out of range.
    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("name", self.name).doc("for messages"));
        visit(field("strength", self.strength)
                  .animatable(self.animation)
                  .range(0, 1e6)
                  .unit("world units/s^2")
                  .doc("the acceleration's root mean square over space, all octaves together"));
        visit(field("size", self.size)
                  .animatable(self.animation)
                  .range(1e-3, 1e6)
                  .unit("world units")
                  .doc("the largest swirls' size"));
        visit(
            field("octaves", self.octaves).range(1, kMaxOctaves).doc("each octave's swirls are half the size of the one before"));
        visit(field("roughness", self.roughness).range(0, 1).doc("each octave's amplitude relative to the one before"));
        visit(field("evolution", self.evolution)
                  .range(0, 1e3)
                  .unit("1/s")
                  .doc("how fast the swirls change: each octave's pattern slides down this many of its own sizes a second"));
        visit(field("seed", self.seed).doc("the swirls' pattern"));
        visit(field("affects", self.affects)
                  .defaultText("everything that moves")
                  .doc("names of the dynamic objects and clouds it acts on; a name that is neither is an error"));
    }
};

/// A TurbulenceSettings's acceleration field.
class Turbulence {
public:
    /// Frame f is at time (f - firstFrame) / fps: where keyed strength and size are read.
    Turbulence(const TurbulenceSettings& spec, int firstFrame, double fps);

    /// The acceleration at p (world) at time t (seconds from the first
    /// frame), world units/s^2: a pure function of both, so any thread and
    /// any shard reads the same.
    Vec3d acceleration(const Vec3d& p, double t) const;

    /// The root mean square of one octave, the cross product of two
    /// independent gradient noises' gradients, in the noise's coordinates:
    /// measured over 4 million points.
    static constexpr double kSwirlRms = 1.2093;

private:
    TurbulenceSettings mSpec;
    GradientNoise mNoise;     ///< n and m: this one noise read at two offsets far apart
    double mOctavesRms = 0.0; ///< the octaves' combined root mean square, at strength 1
    double mScale = 0.0;      ///< strength over mOctavesRms
    int mFirstFrame;
    double mFps;
};

} // namespace vfield
