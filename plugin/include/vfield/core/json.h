#pragma once
/// @file json.h
/// Reading JSON input files (scenes) strictly: every value knows the file and
/// JSON pointer it came from, so an error names both
/// ("cloud.json: /clouds/0/count: expected a positive integer, got -5");
/// a syntax error names its line and column; and a key nobody asked for is an
/// error, so a misspelt key is never silently ignored.
///
/// Readers check kinds here (a number, an integer, [x, y, z]); ranges belong to
/// the options structs (their validate(), core/options.h), and validateAt
/// reports a failure there at the option's JSON path.

#include <vfield/core/math.h>

#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace vfield {

class JsonObject;

/// One JSON value and where it is. Cheap to copy (shares the document).
class JsonValue {
public:
    JsonValue(std::shared_ptr<const nlohmann::json> document, const nlohmann::json* value, std::string file, std::string pointer);

    const std::string& file() const { return mFile; }
    const std::string& pointer() const { return mPointer; } ///< "/clouds/0/count"; "/" for the root
    const nlohmann::json& raw() const { return *mValue; }

    /// Throws ParseError(file, pointer, message).
    [[noreturn]] void fail(const std::string& message) const;

    bool isObject() const;
    bool isString() const;
    bool isNumber() const;
    bool isBool() const;
    bool isArray() const;

    double asNumber() const; ///< any finite number
    /// An integer within the limits of the type it is stored in (a kind
    /// check: ranges of meaning belong to validate()).
    int64_t asInteger(int64_t min, int64_t max) const;
    int asInt() const;           ///< an integer that fits an int
    uint64_t asUnsigned() const; ///< an integer >= 0 (seeds)
    bool asBool() const;
    std::string asString() const;
    /// One of the given names, e.g. {"nearest", "trilinear"}.
    std::string asChoice(const std::vector<std::string>& choices) const;
    Vec3d asVec3() const; ///< [x, y, z]
    Vec2d asVec2() const; ///< [x, y]
    std::vector<JsonValue> asArray() const;
    JsonObject asObject() const;

    /// The value as text for messages, shortened.
    std::string brief() const;

private:
    friend class JsonObject;
    /// A value inside this one, sharing the document; token is its pointer step.
    JsonValue childValue(const nlohmann::json* value, const std::string& token) const;

    std::shared_ptr<const nlohmann::json> mDocument;
    const nlohmann::json* mValue;
    std::string mFile, mPointer;
};

/// An object whose keys are read one by one; finish() refuses the rest.
class JsonObject {
public:
    explicit JsonObject(const JsonValue& value);

    const JsonValue& value() const { return mValue; }
    bool has(const std::string& key) const;
    /// The key's value, if present (marks it read).
    std::optional<JsonValue> find(const std::string& key);
    /// The key's value; an error if missing.
    JsonValue at(const std::string& key);

    // Typed reads with a default for a missing key.
    double number(const std::string& key, double fallback);
    int integer(const std::string& key, int fallback);
    int64_t integer64(const std::string& key, int64_t fallback);
    uint64_t unsignedInteger(const std::string& key, uint64_t fallback);
    bool boolean(const std::string& key, bool fallback);
    std::string string(const std::string& key, const std::string& fallback);
    std::string choice(const std::string& key, const std::string& fallback, const std::vector<std::string>& choices);
    Vec3d vec3(const std::string& key, const Vec3d& fallback);

    /// Throws for the first key (in document order) that was never read.
    void finish() const;

private:
    JsonValue mValue;
    std::set<std::string> mRead;
};

/// Runs validate (an options struct's check); an OptionError it throws becomes
/// a ParseError at the option's path below json ("s.json: /clouds/0/count: ...").
void validateAt(const JsonValue& json, const std::function<void()>& validate);

/// Reads an options struct from a JSON object: starting from the struct's
/// defaults, readKeys(object, options) takes the keys it knows; any other key
/// is an error, and the struct's validate() is reported at its JSON path.
template<typename Options, typename ReadKeys>
Options readOptions(const JsonValue& json, ReadKeys&& readKeys)
{
    JsonObject object(json);
    Options options;
    readKeys(object, options);
    object.finish();
    validateAt(json, [&] { options.validate(); });
    return options;
}

/// The deepest nesting of arrays and objects a JSON input may have; deeper
/// documents are refused before they are parsed.
constexpr int kMaxJsonDepth = 256;

/// Parses a JSON file. Throws FileError if it cannot be read, ParseError with
/// "line L, column C" for a syntax error.
JsonValue readJsonFile(const std::string& path);
/// Parses JSON text that came from `file` (for messages).
JsonValue parseJson(const std::string& text, const std::string& file);

} // namespace vfield
