#pragma once
/// @file field_traits.h
/// What the visitors of a declaration (field_visitors.h) share: the kinds of
/// member a field may hold, and each leaf value read from JSON, written to
/// it and hashed.

#include <vfield/core/animation.h>
#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>
#include <vfield/core/fields.h>
#include <vfield/core/hash.h>
#include <vfield/core/json.h>
#include <vfield/core/options.h>
#include <vfield/core/transform.h>

#include <nlohmann/json.hpp>

#include <map>
#include <set>
#include <string>
#include <vector>

namespace vfield {

namespace detail {

template<typename T>
struct IsOptional : std::false_type {};
template<typename T>
struct IsOptional<std::optional<T>> : std::true_type {};
template<typename T>
struct IsPairRef : std::false_type {};
template<typename T>
struct IsPairRef<PairRef<T>> : std::true_type {
    using type = T;
};
template<typename T>
struct OptionalValue {
    using type = T;
};
template<typename T>
struct OptionalValue<std::optional<T>> {
    using type = T;
};
template<typename T>
struct IsVector : std::false_type {};
template<typename T>
struct IsVector<std::vector<T>> : std::true_type {};
/// A std::vector of structs that declare their fields (an array of objects).
template<typename T>
struct IsSectionList : std::false_type {};
template<typename T>
struct IsSectionList<std::vector<T>> : std::bool_constant<kHasFields<T>> {};
template<typename T>
inline constexpr bool kIsInteger = std::is_same_v<T, int> || std::is_same_v<T, int64_t> || std::is_same_v<T, uint64_t>;

template<typename T>
using Plain = std::remove_const_t<T>;

/// The vector-like leaves and their component counts.
template<typename T>
inline constexpr int kComponents = 0;
template<>
inline constexpr int kComponents<Vec3d> = 3;
template<>
inline constexpr int kComponents<Vec2d> = 2;

// Leaf values to and from JSON. A leaf is anything but a section (a struct
// with fields), an optional or vector of sections, or a proxy.

template<typename T>
T readLeaf(const JsonValue& json)
{
    if constexpr (std::is_same_v<T, double>) return json.asNumber();
    else if constexpr (std::is_same_v<T, int>) return json.asInt();
    else if constexpr (std::is_same_v<T, int64_t>) return json.asInteger(INT64_MIN, INT64_MAX);
    else if constexpr (std::is_same_v<T, uint64_t>) return json.asUnsigned();
    else if constexpr (std::is_same_v<T, bool>) return json.asBool();
    else if constexpr (std::is_same_v<T, std::string>) return json.asString();
    else if constexpr (std::is_same_v<T, Vec3d>) return json.asVec3();
    else if constexpr (std::is_same_v<T, Vec2d>) return json.asVec2();
    else if constexpr (std::is_enum_v<T>) return *enumFromName<T>(json.asChoice(enumNameList<T>()));
    else if constexpr (std::is_same_v<T, Quatd>) return Transform::rotationFromDegrees(json.asVec3());
    else if constexpr (std::is_same_v<T, BBoxd>) {
        JsonObject o(json);
        const Vec3d min = o.at("min").asVec3(), max = o.at("max").asVec3();
        o.finish();
        return BBoxd(min, max);
    } else if constexpr (IsVector<T>::value) {
        T items;
        for (const JsonValue& item : json.asArray()) items.push_back(readLeaf<typename T::value_type>(item));
        return items;
    } else {
        static_assert(sizeof(T) == 0, "no JSON form for this field's type");
    }
}

/// Euler angles in degrees (about x, then y, then z) of a unit quaternion:
/// what Transform::rotationFromDegrees turns back into it.
Vec3d eulerDegrees(const Quatd& rotation);

template<typename T>
nlohmann::json leafToJson(const T& value)
{
    if constexpr (kComponents < T >> 0) {
        nlohmann::json array = nlohmann::json::array();
        for (int i = 0; i < kComponents<T>; ++i) array.push_back(value[i]);
        return array;
    } else if constexpr (std::is_enum_v<T>) {
        return enumName(value);
    } else if constexpr (std::is_same_v<T, Quatd>) {
        return leafToJson(eulerDegrees(value));
    } else if constexpr (std::is_same_v<T, BBoxd>) {
        return {{"min", leafToJson(value.min())}, {"max", leafToJson(value.max())}};
    } else if constexpr (IsVector<T>::value) {
        nlohmann::json array = nlohmann::json::array();
        for (const auto& item : value) array.push_back(leafToJson(item));
        return array;
    } else {
        return value;
    }
}

template<typename T>
void hashLeaf(ContentHash& hash, const T& value)
{
    if constexpr (std::is_same_v<T, std::string>) {
        hash.addValue(uint64_t(value.size()));
        hash.add(value);
    } else if constexpr (kComponents<T> > 0) {
        for (int i = 0; i < kComponents<T>; ++i) hash.addValue(double(value[i]));
    } else if constexpr (std::is_enum_v<T> || std::is_same_v<T, bool> || kIsInteger<T>) {
        hash.addValue(int64_t(value));
    } else if constexpr (std::is_same_v<T, Quatd>) {
        for (int i = 0; i < 4; ++i) hash.addValue(value[i]);
    } else if constexpr (std::is_same_v<T, BBoxd>) {
        hashLeaf(hash, value.min());
        hashLeaf(hash, value.max());
    } else if constexpr (IsVector<T>::value) {
        hash.addValue(uint64_t(value.size()));
        for (const auto& item : value) hashLeaf(hash, item);
    } else {
        hash.addValue(double(value));
    }
}

/// The value type a field's keys hold: the member's, or its optional's.
template<typename V>
using KeyedValue = typename OptionalValue<V>::type;
/// Whether a member of type V may be keyed.
template<typename V>
inline constexpr bool kKeyable = kKeyComponents<KeyedValue<V>> > 0;

/// Whether a JSON value is keys ({"keys": ...}) rather than a constant.
inline bool isKeysObject(const JsonValue& json) { return json.isObject() && json.raw().contains("keys"); }

/// {"keys": [[frame, value], ...], "interpolation": name} read into a track.
template<typename T>
KeyTrack readKeyTrack(const JsonValue& json, bool isDirection)
{
    JsonObject object(json);
    const JsonValue keys = object.at("keys");
    const std::optional<JsonValue> interpolation = object.find("interpolation");
    object.finish();
    std::vector<double> frames, values;
    for (const JsonValue& key : keys.asArray()) {
        const std::vector<JsonValue> pair = key.isArray() ? key.asArray() : std::vector<JsonValue>{};
        if (pair.size() != 2) key.fail("expected a key [frame, value], got " + key.brief());
        const double frame = pair[0].asNumber();
        if (!frames.empty() && !(frame > frames.back()))
            pair[0].fail("expected frames in increasing order, got " + pair[0].brief() + " after " + numberText(frames.back()));
        const T value = readLeaf<T>(pair[1]);
        if constexpr (std::is_same_v<T, Vec3d>)
            if (isDirection && !(value.length() > 0)) pair[1].fail("expected a non-zero vector");
        frames.push_back(frame);
        values.resize(values.size() + kKeyComponents<T>);
        toKeyComponents(value, &values[values.size() - kKeyComponents<T>]);
    }
    if (frames.empty()) keys.fail("expected at least one key [frame, value]");
    return KeyTrack(std::move(frames), std::move(values), kKeyComponents<T>,
                    interpolation ? readLeaf<Interpolation>(*interpolation) : Interpolation::Linear, isDirection);
}

template<typename T>
nlohmann::json keyTrackToJson(const KeyTrack& track)
{
    nlohmann::json keys = nlohmann::json::array();
    for (std::size_t i = 0; i < track.frames().size(); ++i)
        keys.push_back({track.frames()[i], leafToJson(fromKeyComponents<T>(track.value(i)))});
    return {{"keys", keys}, {"interpolation", enumName(track.interpolation())}};
}

inline void hashKeyTrack(ContentHash& hash, const KeyTrack& track)
{
    hash.addValue(uint64_t(track.frames().size()));
    hash.addValue(int64_t(track.interpolation()));
    for (std::size_t i = 0; i < track.frames().size(); ++i) {
        hash.addValue(track.frames()[i]);
        for (int c = 0; c < track.components(); ++c) hash.addValue(track.value(i)[c]);
    }
}

} // namespace detail

} // namespace vfield
