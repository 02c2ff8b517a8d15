#pragma once
/// @file animation.h
/// Values on keys: a setting the declarations mark animatable (fields.h,
/// Field::animatable) takes either a constant or keys over frames,
///
///     "intensity": {"keys": [[1, 3.0], [120, 0.5]], "interpolation": "smooth"}
///
/// as Houdini's channels and Blender's F-curves hold them. The struct keeps
/// its plain member (the constant, or the first key's value) and, beside it,
/// an Animation: the keys of each of its animatable fields that has them.
/// atFrame(settings, f) is the struct with every keyed member set to its
/// value at frame f; the stages read plain members of settings so resolved.

#include <vfield/core/fields.h>
#include <vfield/core/math.h>

#include <string>
#include <utility>
#include <vector>

namespace vfield {

/// How a value goes from one key to the next.
enum class Interpolation {
    Linear, ///< straight, each component on its own
    /// A monotone cubic (Steffen's: "A simple method for monotonic
    /// interpolation in one dimension", 1990): flat at the first and last keys
    /// and at every key that is a peak or a dip of its component, so it eases
    /// in and out and never overshoots its keys.
    Smooth,
    Step ///< holds each key's value until the next key
};
inline constexpr EnumName<Interpolation> kInterpolationNames[] = {
    {Interpolation::Linear, "linear"}, {Interpolation::Smooth, "smooth"}, {Interpolation::Step, "step"}};
constexpr const auto& enumNames(Interpolation) { return kInterpolationNames; }

/// One value's keys: frames (increasing, fractional allowed) and a value of
/// `components` numbers at each. Before the first key it holds the first
/// value, after the last the last.
class KeyTrack {
public:
    /// values holds components numbers per frame, in order. A direction's keys
    /// are normalised and so is every value between them.
    KeyTrack(std::vector<double> frames, std::vector<double> values, int components, Interpolation interpolation,
             bool isDirection);

    /// The value at frame (components numbers into out).
    void evaluate(double frame, double* out) const;
    /// The integral of the first component over frames from..to (to >= from),
    /// exact for every interpolation: what a keyed rate adds up to.
    double integrate(double from, double to) const;

    const std::vector<double>& frames() const { return mFrames; }
    /// Key i's components.
    const double* value(std::size_t i) const { return &mValues[i * std::size_t(mComponents)]; }
    int components() const { return mComponents; }
    Interpolation interpolation() const { return mInterpolation; }

private:
    /// Steffen's slope of each component at each key (Smooth only).
    void computeSlopes();

    std::vector<double> mFrames, mValues, mSlopes;
    int mComponents;
    Interpolation mInterpolation;
    bool mIsDirection;
};

/// The keys of a struct's animatable fields, by the field's key. Empty for a
/// struct whose values are all constant.
class Animation {
public:
    /// The keys of the field `key`, or null when it is constant.
    const KeyTrack* find(const std::string& key) const;
    /// Keys the field `key` (replacing any it had).
    void set(const std::string& key, KeyTrack track);
    /// The field `key` constant again.
    void erase(const std::string& key);
    bool empty() const { return mTracks.empty(); }

private:
    std::vector<std::pair<std::string, KeyTrack>> mTracks;
};

namespace detail {

/// The numbers a value interpolates: one, a vector's components, or a box's
/// min then max.
template<typename T>
inline constexpr int kKeyComponents = std::is_same_v<T, double>  ? 1
                                      : std::is_same_v<T, Vec3d> ? 3
                                      : std::is_same_v<T, Vec2d> ? 2
                                      : std::is_same_v<T, BBoxd> ? 6
                                                                 : 0;

template<typename T>
void toKeyComponents(const T& value, double* out)
{
    if constexpr (std::is_same_v<T, double>) out[0] = value;
    else if constexpr (std::is_same_v<T, BBoxd>) {
        toKeyComponents(value.min(), out);
        toKeyComponents(value.max(), out + 3);
    } else {
        for (int i = 0; i < kKeyComponents<T>; ++i) out[i] = value[i];
    }
}

template<typename T>
T fromKeyComponents(const double* in)
{
    if constexpr (std::is_same_v<T, double>) return in[0];
    else if constexpr (std::is_same_v<T, Vec3d>) return Vec3d(in[0], in[1], in[2]);
    else if constexpr (std::is_same_v<T, Vec2d>) return Vec2d(in[0], in[1]);
    else return BBoxd(Vec3d(in[0], in[1], in[2]), Vec3d(in[3], in[4], in[5]));
}

} // namespace detail

/// The value of a keyed track at frame, as T.
template<typename T>
T keyedValue(const KeyTrack& track, double frame)
{
    double components[6];
    track.evaluate(frame, components);
    return detail::fromKeyComponents<T>(components);
}

/// The field `key`'s value at frame: its keys' if it has them, else constant.
template<typename T>
T valueAtFrame(const Animation& animation, const std::string& key, const T& constant, double frame)
{
    const KeyTrack* track = animation.find(key);
    return track ? keyedValue<T>(*track, frame) : constant;
}

} // namespace vfield
