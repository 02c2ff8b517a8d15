#pragma once
/// @file fields.h
/// Every options struct declares its fields once, in a static member template
///
///     template<typename Self, typename Visitor>
///     static void visitFields(Self& self, Visitor& visit)
///     {
///         visit(field("extinction", self.extinction).range(0, 1e9).unit("1/world units").doc("sigma_t per unit density"));
///         ...
///     }
///
/// (Self is the struct, const or not): the key as a scene file spells it, the
/// member (whose initializer is the default), its range, its unit and one
/// line of documentation. Everything that has to list the fields is derived
/// from that one declaration, in the manner of Mitsuba's traverse() and
/// pbrt's parameter dictionaries (field_visitors.h): reading a scene file's
/// object, range checks, content hashes (the simulation's inputs, the render
/// stamp), JSON export for hosts, command-line flags and the documentation
/// tables of docs/scenes.md (`vfield help keys`). A field added to a
/// declaration reaches all of them; a field left out reaches none, and the
/// tests that walk the declarations see it.
///
/// A member is any of: a number (double, int, int64_t, uint64_t), bool,
/// std::string, Vec3d, Vec2d, an enum with a name table (enumNames(), below),
/// Quatd (written as Euler angles in degrees), BBoxd ({"min", "max"}),
/// std::vector of strings or Vec2d, std::optional of those, a struct that
/// declares its own fields (a nested object), std::optional or std::vector
/// of such a struct. Proxies cover keys that are not one member: pairOf() ([a, b]
/// over two members), uniformOf() (one number for all three of a Vec3d).
/// A number, Vec3d or BBoxd marked animatable() may hold keys over frames
/// instead (animation.h).
/// Sections compose: inlineFields() puts a struct's fields at the current
/// level, group() nests keys of the current struct under an object.

#include <vfield/core/math.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

namespace vfield {

class Animation;

// --- enum names ------------------------------------------------------------------

/// One value of an enum and its name in scene files and on command lines.
template<typename Enum>
struct EnumName {
    Enum value;
    const char* name;
};

/// Each enum used in options declares its one name table beside it, and a
/// function returning it that argument-dependent lookup finds:
///     inline constexpr EnumName<SplitRule> kSplitRuleNames[] = {{SplitRule::NormalCone, "normalCone"}, ...};
///     constexpr const auto& enumNames(SplitRule) { return kSplitRuleNames; }
template<typename Enum>
const char* enumName(Enum value)
{
    for (const auto& entry : enumNames(Enum{}))
        if (entry.value == value) return entry.name;
    return "?";
}

/// The value named `name`, if any.
template<typename Enum>
std::optional<Enum> enumFromName(const std::string& name)
{
    for (const auto& entry : enumNames(Enum{}))
        if (name == entry.name) return entry.value;
    return std::nullopt;
}

/// Every name, in declaration order.
template<typename Enum>
std::vector<std::string> enumNameList()
{
    std::vector<std::string> names;
    for (const auto& entry : enumNames(Enum{})) names.push_back(entry.name);
    return names;
}

// --- proxies: keys that are not one member -------------------------------------

/// [first, second] in a file, two members in the struct ("size": sizeX, sizeZ).
template<typename T>
struct PairRef {
    T* first;
    T* second;
    const char* names; ///< as messages and documentation show the pair: "x, z"
};
template<typename T>
PairRef<T> pairOf(T& first, T& second, const char* names)
{
    return {&first, &second, names};
}

/// One number in a file standing for all three components of a Vec3d
/// (a sphere's "radius" is its three radii).
template<typename V>
struct UniformRef {
    V* vector;
};
template<typename V>
UniformRef<V> uniformOf(V& vector)
{
    return {&vector};
}

namespace detail {
template<typename T>
struct IsProxy : std::false_type {};
template<typename T>
struct IsProxy<PairRef<T>> : std::true_type {};
template<typename V>
struct IsProxy<UniformRef<V>> : std::true_type {};
} // namespace detail

// --- a field -----------------------------------------------------------------------

/// What a declaration says of one key. T is the member's type, const when
/// the struct is visited read-only; or a proxy (PairRef, UniformRef).
template<typename T>
class Field {
public:
    /// How the member is held: by pointer, or a proxy by value.
    using Ref = std::conditional_t<detail::IsProxy<std::remove_const_t<T>>::value, std::remove_const_t<T>, T*>;

    Field(const char* key, Ref ref) : mKey(key), mRef(ref) {}

    /// The closed range of a number, an integer, or each component of a vector.
    Field& range(double min, double max)
    {
        mMin = min;
        mMax = max;
        return *this;
    }
    Field& atLeast(double min) { return range(min, std::numeric_limits<double>::infinity()); }
    Field& unit(const char* unit)
    {
        mUnit = unit;
        return *this;
    }
    Field& doc(const char* doc)
    {
        mDoc = doc;
        return *this;
    }
    /// The default as the documentation states it, where the member's
    /// initializer stands for a value computed later ("10% of the largest extent").
    Field& defaultText(const char* text)
    {
        mDefaultText = text;
        return *this;
    }
    /// The key must be present (where the field applies).
    Field& required(bool isRequired = true)
    {
        mRequired = isRequired;
        return *this;
    }
    /// The key applies only when `applies`; otherwise it is refused with
    /// "\"key\" <reason>" ("applies to dynamic objects only"). Fields read
    /// in declaration order, so `applies` may depend on fields before it.
    Field& onlyWhen(bool applies, const char* reason)
    {
        mApplies = applies;
        mNotApplyingReason = reason;
        return *this;
    }
    /// A file named relative to the scene file's folder; its bytes enter the
    /// content hashes (an edited mesh file is another simulation).
    Field& isPath()
    {
        mIsPath = true;
        return *this;
    }
    /// A vector that must not be zero.
    Field& nonZero()
    {
        mNonZero = true;
        return *this;
    }
    /// A direction: a non-zero vector whose length means nothing; keyed, its
    /// keys and every value between them are unit vectors.
    Field& isDirection()
    {
        mIsDirection = true;
        return nonZero();
    }
    /// The key may hold keys over frames instead of a constant (animation.h):
    /// they are kept in `animation`, the struct's, and the member holds the
    /// first key's value.
    Field& animatable(Animation& animation)
    {
        mAnimation = &animation;
        mKeys = &animation;
        return *this;
    }
    Field& animatable(const Animation& animation)
    {
        mKeys = &animation;
        return *this;
    }
    /// An optional object that may also be given as true (present, with its
    /// defaults) or false (absent).
    Field& orBoolean()
    {
        mOrBoolean = true;
        return *this;
    }
    /// A boolean written as one of two names ("static" or "dynamic").
    Field& names(const char* falseName, const char* trueName)
    {
        mFalseName = falseName;
        mTrueName = trueName;
        return *this;
    }
    /// The key selects an alternative: its presence sets *member to value,
    /// and exactly one key of the same member must be present. It applies
    /// when *member == value.
    template<typename Enum>
    Field& selects(Enum& member, Enum value)
    {
        mSelector = &member;
        mApplies = member == value;
        mSelect = [&member, value] { member = value; };
        return *this;
    }
    template<typename Enum>
    Field& selects(const Enum& member, Enum value)
    {
        mSelector = &member;
        mApplies = member == value;
        return *this;
    }

    const char* key() const { return mKey; }
    const Ref& ref() const { return mRef; }
    double min() const { return mMin; }
    double max() const { return mMax; }
    const char* unitText() const { return mUnit; }
    const char* docText() const { return mDoc; }
    const char* defaultOverride() const { return mDefaultText; }
    bool isRequired() const { return mRequired; }
    bool applies() const { return mApplies; }
    const char* notApplyingReason() const { return mNotApplyingReason; }
    bool pathValued() const { return mIsPath; }
    bool mustBeNonZero() const { return mNonZero; }
    bool direction() const { return mIsDirection; }
    /// Where the struct keeps its fields' keys, if this one is animatable.
    const Animation* keys() const { return mKeys; }
    /// The same, to read keys into (null when the struct is visited read-only).
    Animation* animation() const { return mAnimation; }
    bool acceptsBoolean() const { return mOrBoolean; }
    /// A boolean's two names, or null when it is written true or false.
    const char* falseName() const { return mFalseName; }
    const char* trueName() const { return mTrueName; }
    /// The member an alternative's key sets (null when it selects none).
    const void* selector() const { return mSelector; }
    void select() const
    {
        if (mSelect) mSelect();
    }

private:
    const char* mKey;
    Ref mRef;
    double mMin = -std::numeric_limits<double>::infinity(), mMax = std::numeric_limits<double>::infinity();
    const char* mUnit = "";
    const char* mDoc = "";
    const char* mDefaultText = nullptr;
    bool mRequired = false, mApplies = true, mIsPath = false, mNonZero = false, mOrBoolean = false, mIsDirection = false;
    const Animation* mKeys = nullptr;
    Animation* mAnimation = nullptr;
    const char* mNotApplyingReason = "does not apply here";
    const char *mFalseName = nullptr, *mTrueName = nullptr;
    const void* mSelector = nullptr;
    std::function<void()> mSelect;
};

template<typename T>
Field<T> field(const char* key, T& member)
{
    return Field<T>(key, &member);
}
template<typename T>
Field<PairRef<T>> field(const char* key, PairRef<T> pair)
{
    return Field<PairRef<T>>(key, pair);
}
template<typename V>
Field<UniformRef<V>> field(const char* key, UniformRef<V> uniform)
{
    return Field<UniformRef<V>>(key, uniform);
}

// --- sections ----------------------------------------------------------------------

/// A struct's fields placed at the current level of the file (a scene's
/// "render" object holds the image's, the medium's and the integrator's).
template<typename Struct>
struct InlineFields {
    Struct* value;
};
template<typename Struct>
InlineFields<Struct> inlineFields(Struct& value)
{
    return {&value};
}

/// Keys of the current struct nested under an object of the file ("frames":
/// {"start", "end", "fps"}). declare(visitor) visits the nested fields.
template<typename Declare>
struct Group {
    const char* key;
    const char* doc;
    Declare declare;
};
template<typename Declare>
Group<Declare> group(const char* key, const char* doc, Declare declare)
{
    return {key, doc, std::move(declare)};
}

namespace detail {
/// Whether T declares its fields (a section of the file).
template<typename T, typename = void>
struct HasFields : std::false_type {};
struct NullVisitor {
    template<typename X>
    void operator()(const X&)
    {}
};
template<typename T>
struct HasFields<T, std::void_t<decltype(T::visitFields(std::declval<T&>(), std::declval<NullVisitor&>()))>> : std::true_type {};
} // namespace detail

template<typename T>
inline constexpr bool kHasFields = detail::HasFields<std::remove_const_t<T>>::value;

} // namespace vfield
