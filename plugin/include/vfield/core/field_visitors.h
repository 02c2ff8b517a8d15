#pragma once
/// @file field_visitors.h
/// What is derived from an options struct's one declaration of its fields
/// (fields.h):
///   readFields<T>(json, baseDir)  a scene file's object -> T, kinds checked,
///                                 unknown keys refused (ranges: validate())
///   checkFields(value)            every declared range, nested structs' validate()
///   hashFields(hash, value)       every field into a content hash
///   fieldsToJson(value)           the struct as a scene file writes it
///   describeFields<T>()           the documentation tables (`vfield help keys`)
/// Include this in .cpp files only: it brings nlohmann's JSON with it.

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

} // namespace detail

// --- reading ---------------------------------------------------------------------

/// Reads the declared keys of one JSON object into a struct; kinds are
/// checked here (a number, [x, y, z], one of the names), ranges by validate().
class FieldReader {
public:
    FieldReader(JsonObject& object, std::string baseDir) : mObject(object), mBaseDir(std::move(baseDir)) {}

    template<typename T>
    void operator()(const Field<T>& f)
    {
        using V = detail::Plain<T>;
        const std::optional<JsonValue> json = mObject.find(f.key());
        if (f.selector()) countSelection(f, json.has_value());
        if (!json) {
            if (f.isRequired() && f.applies()) mObject.value().fail("missing key \"" + std::string(f.key()) + "\"");
            return;
        }
        if (f.selector()) f.select();
        else if (!f.applies()) json->fail("\"" + std::string(f.key()) + "\" " + f.notApplyingReason());
        read(f, *json, static_cast<V*>(nullptr));
    }

    template<typename S>
    void operator()(const InlineFields<S>& section)
    {
        S::visitFields(*section.value, *this);
    }

    template<typename Declare>
    void operator()(const Group<Declare>& g)
    {
        const std::optional<JsonValue> json = mObject.find(g.key);
        if (!json) return;
        JsonObject nested(*json);
        FieldReader reader(nested, mBaseDir);
        g.declare(reader);
        reader.finish();
    }

    /// After the struct's fields: refuses a missing or second alternative, then unread keys.
    void finish() const
    {
        for (const auto& [selector, keys] : mSelections) {
            if (keys.present == 1) continue;
            std::string list;
            for (const std::string& key : keys.keys) list += (list.empty() ? "\"" : ", \"") + key + "\"";
            mObject.value().fail("expected exactly one of " + list);
        }
        mObject.finish();
    }

private:
    struct Selection {
        std::vector<std::string> keys;
        int present = 0;
    };
    template<typename T>
    void countSelection(const Field<T>& f, bool present)
    {
        Selection& s = mSelections[f.selector()];
        s.keys.push_back(f.key());
        s.present += present ? 1 : 0;
    }

    std::string resolvePath(const std::string& path) const;

    template<typename T, typename V>
    void read(const Field<T>& f, const JsonValue& json, V*)
    {
        if constexpr (kHasFields<V>) {
            *f.ref() = readSection<V>(json);
        } else if constexpr (detail::IsOptional<V>::value) {
            using Inner = typename V::value_type;
            if constexpr (kHasFields<Inner>) {
                if (f.acceptsBoolean() && json.isBool()) {
                    if (json.asBool()) *f.ref() = Inner{};
                    else f.ref()->reset();
                } else {
                    *f.ref() = readSection<Inner>(json);
                }
            } else {
                *f.ref() = detail::readLeaf<Inner>(json);
            }
        } else if constexpr (detail::IsSectionList<V>::value) {
            f.ref()->clear();
            for (const JsonValue& item : json.asArray()) f.ref()->push_back(readSection<typename V::value_type>(item));
        } else if constexpr (detail::IsProxy<V>::value) {
            readProxy(f.ref(), json);
        } else if constexpr (std::is_same_v<V, std::string>) {
            const std::string text = json.asString();
            *f.ref() = f.pathValued() ? resolvePath(text) : text;
        } else if constexpr (std::is_same_v<V, bool>) {
            *f.ref() = f.trueName() ? json.asChoice({f.falseName(), f.trueName()}) == f.trueName() : json.asBool();
        } else {
            *f.ref() = detail::readLeaf<V>(json);
        }
    }

    template<typename X>
    void readProxy(const PairRef<X>& pair, const JsonValue& json)
    {
        const std::vector<JsonValue> items = json.isArray() ? json.asArray() : std::vector<JsonValue>{};
        if (items.size() != 2) json.fail("expected [" + std::string(pair.names) + "], got " + json.brief());
        *pair.first = detail::readLeaf<X>(items[0]);
        *pair.second = detail::readLeaf<X>(items[1]);
    }
    template<typename X>
    void readProxy(const UniformRef<X>& uniform, const JsonValue& json)
    {
        *uniform.vector = X(json.asNumber());
    }

    template<typename S>
    S readSection(const JsonValue& json)
    {
        S value;
        JsonObject object(json);
        FieldReader reader(object, mBaseDir);
        S::visitFields(value, reader);
        reader.finish();
        return value;
    }

    JsonObject& mObject;
    std::string mBaseDir;
    std::map<const void*, Selection> mSelections;
};

/// A struct from a scene file's object, kinds checked, unknown keys refused;
/// paths resolve against baseDir. Ranges are validate()'s: see readValidated.
template<typename T>
T readFields(const JsonValue& json, const std::string& baseDir = {})
{
    T value;
    JsonObject object(json);
    FieldReader reader(object, baseDir);
    T::visitFields(value, reader);
    reader.finish();
    return value;
}

/// readFields, then the struct's validate() reported at its JSON path.
template<typename T>
T readValidated(const JsonValue& json, const std::string& baseDir = {})
{
    T value = readFields<T>(json, baseDir);
    validateAt(json, [&] { value.validate(); });
    return value;
}

// --- checking ----------------------------------------------------------------------

/// The declared ranges of one struct (keys under prefix); nested structs run
/// their own validate(), which checks their fields and what relates them.
class FieldChecker {
public:
    explicit FieldChecker(std::string prefix = {}) : mPrefix(std::move(prefix)) {}

    template<typename T>
    void operator()(const Field<T>& f)
    {
        if (!f.applies()) return;
        check(f, mPrefix + f.key(), static_cast<detail::Plain<T>*>(nullptr));
    }
    template<typename S>
    void operator()(const InlineFields<S>& section)
    {
        if (mPrefix.empty()) section.value->validate();
        else validatePart(mPrefix.substr(0, mPrefix.size() - 1), *section.value);
    }
    template<typename Declare>
    void operator()(const Group<Declare>& g)
    {
        FieldChecker nested(mPrefix + g.key + "/");
        g.declare(nested);
    }

private:
    template<typename T, typename V>
    void check(const Field<T>& f, const std::string& key, V*)
    {
        if constexpr (kHasFields<V>) {
            validatePart(key, *f.ref());
        } else if constexpr (detail::IsOptional<V>::value) {
            if (*f.ref()) checkValue(f, key, **f.ref());
        } else if constexpr (detail::IsSectionList<V>::value) {
            for (std::size_t i = 0; i < f.ref()->size(); ++i) validatePart(key + "/" + std::to_string(i), (*f.ref())[i]);
        } else if constexpr (detail::IsProxy<V>::value) {
            checkProxy(f, key, f.ref());
        } else {
            checkValue(f, key, *f.ref());
        }
    }

    template<typename T, typename X>
    void checkValue(const Field<T>& f, const std::string& key, const X& value)
    {
        if constexpr (kHasFields<X>) {
            validatePart(key, value);
        } else if constexpr (std::is_same_v<X, double>) {
            requireNumber(key, value, f.min(), f.max());
        } else if constexpr (detail::kIsInteger<X>) {
            requireInteger(key, int64_t(value), clampToInteger(f.min()), clampToInteger(f.max()));
        } else if constexpr (detail::kComponents<X> > 0) {
            if (f.mustBeNonZero()) require(value.length() > 0, key, "expected a non-zero vector");
            for (int i = 0; i < detail::kComponents<X>; ++i)
                if (f.min() > -std::numeric_limits<double>::infinity() || f.max() < std::numeric_limits<double>::infinity())
                    requireNumber(key + "/" + std::to_string(i), value[i], f.min(), f.max());
        } else if constexpr (std::is_same_v<X, BBoxd>) {
            for (int axis = 0; axis < 3; ++axis)
                require(value.max()[axis] > value.min()[axis], key, "max must exceed min on every axis");
        }
    }

    template<typename T, typename X>
    void checkProxy(const Field<T>& f, const std::string& key, const PairRef<X>& pair)
    {
        checkValue(f, key + "/0", *pair.first);
        checkValue(f, key + "/1", *pair.second);
    }
    template<typename T, typename X>
    void checkProxy(const Field<T>& f, const std::string& key, const UniformRef<X>& uniform)
    {
        for (int i = 0; i < detail::kComponents<X>; ++i) requireNumber(key, (*uniform.vector)[i], f.min(), f.max());
    }

    static int64_t clampToInteger(double bound)
    {
        return bound <= double(INT64_MIN) ? INT64_MIN : bound >= double(INT64_MAX) ? INT64_MAX : int64_t(bound);
    }

    std::string mPrefix;
};

/// Checks every declared field of value (for its validate()).
template<typename T>
void checkFields(const T& value)
{
    FieldChecker checker;
    T::visitFields(value, checker);
}

// --- hashing -----------------------------------------------------------------------

/// Every declared field of a struct, nested ones included, into a content
/// hash, each behind its key (so that two fields cannot trade values
/// unseen). With file contents, a path field's file is hashed by its bytes.
class FieldHasher {
public:
    FieldHasher(ContentHash& hash, bool withFileContents) : mHash(hash), mWithFileContents(withFileContents) {}

    template<typename T>
    void operator()(const Field<T>& f)
    {
        // A field that does not apply (another alternative, a dynamic
        // object's key on a static one) shapes nothing.
        detail::hashLeaf(mHash, std::string(f.key()));
        mHash.addValue(int64_t(f.applies()));
        if (f.applies()) hashValue(f, *pointer(f));
    }
    template<typename S>
    void operator()(const InlineFields<S>& section)
    {
        S::visitFields(*section.value, *this);
    }
    template<typename Declare>
    void operator()(const Group<Declare>& g)
    {
        detail::hashLeaf(mHash, std::string(g.key));
        g.declare(*this);
    }

private:
    template<typename T>
    static auto pointer(const Field<T>& f)
    {
        if constexpr (detail::IsProxy<detail::Plain<T>>::value) return &f.ref();
        else return f.ref();
    }

    template<typename T, typename X>
    void hashValue(const Field<T>& f, const X& value)
    {
        if constexpr (kHasFields<X>) {
            X::visitFields(value, *this);
        } else if constexpr (detail::IsOptional<X>::value) {
            mHash.addValue(int64_t(value.has_value()));
            if (value) hashValue(f, *value);
        } else if constexpr (detail::IsSectionList<X>::value) {
            mHash.addValue(uint64_t(value.size()));
            for (const auto& item : value) hashValue(f, item);
        } else if constexpr (detail::IsProxy<X>::value) {
            hashProxy(value);
        } else {
            detail::hashLeaf(mHash, value);
            if constexpr (std::is_same_v<X, std::string>)
                if (f.pathValued() && mWithFileContents) detail::hashLeaf(mHash, readFileBytes(value));
        }
    }
    template<typename X>
    void hashProxy(const PairRef<X>& pair)
    {
        detail::hashLeaf(mHash, *pair.first);
        detail::hashLeaf(mHash, *pair.second);
    }
    template<typename X>
    void hashProxy(const UniformRef<X>& uniform)
    {
        detail::hashLeaf(mHash, *uniform.vector);
    }

    ContentHash& mHash;
    bool mWithFileContents;
};

/// Adds every declared field of value to hash; with file contents, the bytes
/// of the files its path fields name (FileError when one cannot be read).
template<typename T>
void hashFields(ContentHash& hash, const T& value, bool withFileContents = false)
{
    FieldHasher hasher(hash, withFileContents);
    T::visitFields(value, hasher);
}

// --- writing -----------------------------------------------------------------------

/// A struct as a scene file writes it: every field that applies.
class FieldWriter {
public:
    explicit FieldWriter(nlohmann::json& object) : mObject(object) {}

    template<typename T>
    void operator()(const Field<T>& f)
    {
        if (!f.applies()) return;
        using V = detail::Plain<T>;
        if constexpr (detail::IsProxy<V>::value) {
            mObject[f.key()] = proxyToJson(f.ref());
        } else if constexpr (detail::IsOptional<V>::value) {
            if (*f.ref()) mObject[f.key()] = valueToJson(**f.ref());
            else if (f.acceptsBoolean()) mObject[f.key()] = false;
        } else if constexpr (std::is_same_v<V, bool>) {
            mObject[f.key()] = f.trueName() ? nlohmann::json(*f.ref() ? f.trueName() : f.falseName()) : nlohmann::json(*f.ref());
        } else {
            mObject[f.key()] = valueToJson(*f.ref());
        }
    }
    template<typename S>
    void operator()(const InlineFields<S>& section)
    {
        S::visitFields(*section.value, *this);
    }
    template<typename Declare>
    void operator()(const Group<Declare>& g)
    {
        nlohmann::json nested = nlohmann::json::object();
        FieldWriter writer(nested);
        g.declare(writer);
        mObject[g.key] = nested;
    }

private:
    template<typename X>
    static nlohmann::json valueToJson(const X& value)
    {
        if constexpr (kHasFields<X>) {
            nlohmann::json object = nlohmann::json::object();
            FieldWriter writer(object);
            X::visitFields(value, writer);
            return object;
        } else if constexpr (detail::IsSectionList<X>::value) {
            nlohmann::json array = nlohmann::json::array();
            for (const auto& item : value) array.push_back(valueToJson(item));
            return array;
        } else {
            return detail::leafToJson(value);
        }
    }
    template<typename X>
    static nlohmann::json proxyToJson(const PairRef<X>& pair)
    {
        return {*pair.first, *pair.second};
    }
    template<typename X>
    static nlohmann::json proxyToJson(const UniformRef<X>& uniform)
    {
        return (*uniform.vector)[0];
    }

    nlohmann::json& mObject;
};

/// The struct's fields that apply, as a JSON object a scene file could hold.
template<typename T>
nlohmann::json fieldsToJson(const T& value)
{
    nlohmann::json object = nlohmann::json::object();
    FieldWriter writer(object);
    T::visitFields(value, writer);
    return object;
}

// --- documenting -----------------------------------------------------------------

/// One key of a documentation table.
struct FieldDoc {
    std::string key;  ///< as in the file ("count"; "frames.start" inside a group)
    std::string type; ///< "number", "integer", "[x, y, z]", "\"a\" or \"b\"", "object", ...
    std::string defaultText;
    std::string meaning; ///< the doc line, with the unit and range
    std::string section; ///< for an object: the table that documents its keys
};

/// A table of keys: one per struct, titled by its place in the file.
struct FieldTable {
    std::string title; ///< "clouds[]", "objects[].mesh.terrain", ...
    std::vector<FieldDoc> rows;
};

namespace detail {
std::string numberDocText(double value);
std::string rangeDocText(double min, double max, bool isInteger);

template<typename T>
std::string typeDocText()
{
    if constexpr (std::is_same_v<T, double>) return "number";
    else if constexpr (kIsInteger<T>) return std::is_same_v<T, uint64_t> ? "integer >= 0" : "integer";
    else if constexpr (std::is_same_v<T, bool>) return "boolean";
    else if constexpr (std::is_same_v<T, std::string>) return "string";
    else if constexpr (std::is_same_v<T, Vec3d>) return "[x, y, z]";
    else if constexpr (std::is_same_v<T, Vec2d>) return "[x, z]";
    else if constexpr (std::is_same_v<T, Quatd>) return "[x, y, z] degrees";
    else if constexpr (std::is_same_v<T, BBoxd>) return "{\"min\", \"max\"}";
    else if constexpr (std::is_enum_v<T>) {
        std::string text;
        const std::vector<std::string> names = enumNameList<T>();
        for (std::size_t i = 0; i < names.size(); ++i)
            text += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + ("`\"" + names[i] + "\"`");
        return text;
    } else if constexpr (IsVector<T>::value) return "array of " + typeDocText<typename T::value_type>();
    else return "object";
}

template<typename T>
std::string valueDocText(const T& value)
{
    if constexpr (std::is_same_v<T, double>) return "`" + numberDocText(value) + "`";
    else if constexpr (kComponents<T> > 0) {
        std::string text = "`[";
        for (int i = 0; i < kComponents<T>; ++i) text += (i ? ", " : "") + numberDocText(value[i]);
        return text + "]`";
    } else if constexpr (std::is_enum_v<T>) return std::string("`\"") + enumName(value) + "\"`";
    else if constexpr (std::is_same_v<T, std::string>) return "`\"" + value + "\"`";
    else {
        std::string text = leafToJson(value).dump();
        std::string spaced;
        for (const char c : text) spaced += c == ',' ? std::string(", ") : std::string(1, c);
        return "`" + spaced + "`";
    }
}
} // namespace detail

/// Gathers the documentation of a struct and the structs below it, from a
/// default-constructed value (its defaults): a table per object of the file.
class FieldDocumenter {
public:
    /// Appends the table `title` to tables; its nested objects' tables follow it.
    FieldDocumenter(std::vector<FieldTable>& tables, std::string title)
        : mTables(tables), mTable(tables.size()), mTitle(std::move(title))
    {
        mTables.push_back({mTitle, {}});
    }

    template<typename T>
    void operator()(const Field<T>& f)
    {
        using V = detail::Plain<T>;
        FieldDoc row;
        row.key = f.key();
        row.meaning = f.docText();
        describe(f, row, static_cast<V*>(nullptr));
        const std::string unitAndRange = unitAndRangeText(f, static_cast<V*>(nullptr));
        if (!unitAndRange.empty()) row.meaning += (row.meaning.empty() ? "" : "; ") + unitAndRange;
        if (f.defaultOverride()) row.defaultText = f.defaultOverride();
        if (f.isRequired()) row.defaultText = "required";
        if (f.selector()) row.defaultText = ""; // one alternative is given, none is the default
        mTables[mTable].rows.push_back(std::move(row));
    }
    template<typename S>
    void operator()(const InlineFields<S>& section)
    {
        S::visitFields(*section.value, *this);
    }
    template<typename Declare>
    void operator()(const Group<Declare>& g)
    {
        FieldDoc row;
        row.key = g.key;
        row.type = "object";
        row.defaultText = "see its table";
        row.meaning = g.doc;
        row.section = childTitle(g.key);
        FieldDocumenter nested(mTables, row.section);
        g.declare(nested);
        mTables[mTable].rows.push_back(std::move(row));
    }

private:
    template<typename T, typename V>
    void describe(const Field<T>& f, FieldDoc& row, V*)
    {
        if constexpr (kHasFields<V>) {
            row.type = "object";
            row.defaultText = "see its table";
            row.section = childTitle(f.key());
            documentSection<V>(*f.ref(), row.section);
        } else if constexpr (detail::IsOptional<V>::value) {
            using Inner = typename V::value_type;
            if constexpr (kHasFields<Inner>) {
                row.type = f.acceptsBoolean() ? "object, `true` or `false`" : "object";
                row.defaultText = *f.ref() ? (f.acceptsBoolean() ? "`true` (its defaults)" : "see its table") : "none";
                row.section = childTitle(f.key());
                documentSection<Inner>(Inner{}, row.section);
            } else {
                row.type = detail::typeDocText<Inner>();
                row.defaultText = *f.ref() ? detail::valueDocText(**f.ref()) : "none";
            }
        } else if constexpr (detail::IsSectionList<V>::value) {
            row.type = "array of objects";
            row.defaultText = "`[]`";
            row.section = childTitle(f.key()) + "[]";
            documentSection<typename V::value_type>(typename V::value_type{}, row.section);
        } else if constexpr (detail::IsProxy<V>::value) {
            describeProxy(f.ref(), row);
        } else if constexpr (std::is_same_v<V, bool>) {
            row.type = f.trueName() ? "`\"" + std::string(f.falseName()) + "\"` or `\"" + f.trueName() + "\"`" : "boolean";
            row.defaultText = f.trueName() ? "`\"" + std::string(*f.ref() ? f.trueName() : f.falseName()) + "\"`"
                                           : (*f.ref() ? "`true`" : "`false`");
        } else {
            row.type = detail::typeDocText<V>();
            row.defaultText = detail::valueDocText(*f.ref());
        }
    }
    template<typename X>
    static void describeProxy(const PairRef<X>& pair, FieldDoc& row)
    {
        row.type = "[" + std::string(pair.names) + "]";
        row.defaultText =
            "`[" + stripTicks(detail::valueDocText(*pair.first)) + ", " + stripTicks(detail::valueDocText(*pair.second)) + "]`";
    }
    template<typename X>
    static void describeProxy(const UniformRef<X>& uniform, FieldDoc& row)
    {
        row.type = "number";
        row.defaultText = detail::valueDocText((*uniform.vector)[0]);
    }
    static std::string stripTicks(const std::string& text) { return text.substr(1, text.size() - 2); }

    template<typename T, typename V>
    static std::string unitAndRangeText(const Field<T>& f, V*)
    {
        using Value = std::conditional_t<detail::IsOptional<V>::value, typename detail::OptionalValue<V>::type, V>;
        std::string text = f.unitText();
        const std::string range = detail::rangeDocText(f.min(), f.max(), detail::kIsInteger<Value> || isIntegerProxy<Value>());
        if (!range.empty()) text += (text.empty() ? "" : ", ") + range;
        if (f.mustBeNonZero()) text += (text.empty() ? "" : ", ") + std::string("non-zero");
        return text;
    }
    template<typename V>
    static constexpr bool isIntegerProxy()
    {
        if constexpr (detail::IsPairRef<V>::value)
            return detail::kIsInteger<std::remove_const_t<typename detail::IsPairRef<V>::type>>;
        else return false;
    }

    /// "objects[].mesh": the place of a key's object in the file.
    std::string childTitle(const char* key) const { return mTitle == kSceneTitle ? std::string(key) : mTitle + "." + key; }
    template<typename S>
    void documentSection(const S& defaults, const std::string& title)
    {
        FieldDocumenter nested(mTables, title);
        S::visitFields(defaults, nested);
    }

    static constexpr const char* kSceneTitle = "scene";
    std::vector<FieldTable>& mTables;
    std::size_t mTable;
    std::string mTitle;
};

/// The documentation tables of T and the structs below it, from its
/// defaults; T's own table is titled "scene", the others by their place
/// ("objects[].mesh.terrain").
template<typename T>
std::vector<FieldTable> describeFields()
{
    std::vector<FieldTable> tables;
    const T defaults{};
    FieldDocumenter documenter(tables, "scene");
    T::visitFields(defaults, documenter);
    return tables;
}

/// A table as Markdown: | key | type | default | meaning |.
std::string markdownTable(const FieldTable& table);

} // namespace vfield
