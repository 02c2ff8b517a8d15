#pragma once
/// @file field_reader.h
/// A scene file's object read into a struct by its declaration (fields.h),
/// and the declared ranges checked.

#include <vfield/core/field_traits.h>

namespace vfield {

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
        if constexpr (detail::kKeyable<V>) {
            if (Animation* animation = f.animation()) {
                if (detail::isKeysObject(*json)) return readKeys(f, *animation, *json);
                animation->erase(f.key());
            }
        }
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

    /// Keys in place of a constant: kept in the struct's animation, the
    /// member set to the first key's value.
    template<typename T>
    void readKeys(const Field<T>& f, Animation& animation, const JsonValue& json)
    {
        using Value = detail::KeyedValue<detail::Plain<T>>;
        KeyTrack track = detail::readKeyTrack<Value>(json, f.direction());
        *f.ref() = detail::fromKeyComponents<Value>(track.value(0));
        animation.set(f.key(), std::move(track));
    }

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

/// The declared ranges of one struct (keys under prefix); nested structs run
/// their own validate(), which checks their fields and what relates them.
class FieldChecker {
public:
    explicit FieldChecker(std::string prefix = {}) : mPrefix(std::move(prefix)) {}

    template<typename T>
    void operator()(const Field<T>& f)
    {
        if (!f.applies()) return;
        using V = detail::Plain<T>;
        if constexpr (detail::kKeyable<V>) {
            if (const KeyTrack* track = f.keys() ? f.keys()->find(f.key()) : nullptr) return checkKeys(f, *track);
        }
        check(f, mPrefix + f.key(), static_cast<V*>(nullptr));
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

    /// Every key's value, each reported at its place ("sun/intensity/keys/2/1").
    template<typename T>
    void checkKeys(const Field<T>& f, const KeyTrack& track)
    {
        using Value = detail::KeyedValue<detail::Plain<T>>;
        for (std::size_t i = 0; i < track.frames().size(); ++i)
            checkValue(f, mPrefix + f.key() + "/keys/" + std::to_string(i) + "/1",
                       detail::fromKeyComponents<Value>(track.value(i)));
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

} // namespace vfield
