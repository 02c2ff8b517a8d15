#include <vfield/core/json.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <sstream>

namespace vfield {

namespace {

std::string escapePointerToken(const std::string& key)
{
    std::string out;
    for (char c : key) {
        if (c == '~') out += "~0";
        else if (c == '/') out += "~1";
        else out += c;
    }
    return out;
}

std::string child(const std::string& pointer, const std::string& token)
{
    return (pointer == "/" ? std::string() : pointer) + "/" + token;
}

} // namespace

JsonValue::JsonValue(std::shared_ptr<const nlohmann::json> document, const nlohmann::json* value, std::string file,
                     std::string pointer)
    : mDocument(std::move(document)), mValue(value), mFile(std::move(file)), mPointer(std::move(pointer))
{}

void JsonValue::fail(const std::string& message) const { throw ParseError(mFile, mPointer, message); }

bool JsonValue::isObject() const { return mValue->is_object(); }
bool JsonValue::isString() const { return mValue->is_string(); }
bool JsonValue::isNumber() const { return mValue->is_number(); }
bool JsonValue::isBool() const { return mValue->is_boolean(); }
bool JsonValue::isArray() const { return mValue->is_array(); }

std::string JsonValue::brief() const
{
    std::string text = mValue->dump();
    if (text.size() > 40) text = text.substr(0, 37) + "...";
    return text;
}

double JsonValue::asNumber() const
{
    if (!mValue->is_number()) fail("expected a number, got " + brief());
    const double v = mValue->get<double>();
    if (!std::isfinite(v)) fail("expected a finite number, got " + brief());
    return v;
}

int64_t JsonValue::asInteger(int64_t min, int64_t max) const
{
    const std::string kind = min == 1 ? "a positive integer" : min == 0 ? "a non-negative integer" : "an integer";
    if (!mValue->is_number()) fail("expected " + kind + ", got " + brief());
    const double v = mValue->get<double>();
    if (!std::isfinite(v) || std::floor(v) != v || v < double(min)) fail("expected " + kind + ", got " + brief());
    if (v > double(max)) fail("expected " + kind + " of at most " + std::to_string(max) + ", got " + brief());
    return mValue->is_number_integer() ? mValue->get<int64_t>() : int64_t(v);
}

int JsonValue::asInt() const { return int(asInteger(INT32_MIN, INT32_MAX)); }

uint64_t JsonValue::asUnsigned() const
{
    if (mValue->is_number_unsigned()) return mValue->get<uint64_t>();
    return uint64_t(asInteger(0, INT64_MAX));
}

bool JsonValue::asBool() const
{
    if (!mValue->is_boolean()) fail("expected true or false, got " + brief());
    return mValue->get<bool>();
}

std::string JsonValue::asString() const
{
    if (!mValue->is_string()) fail("expected a string, got " + brief());
    return mValue->get<std::string>();
}

std::string JsonValue::asChoice(const std::vector<std::string>& choices) const
{
    const std::string v = mValue->is_string() ? mValue->get<std::string>() : std::string();
    for (const std::string& c : choices)
        if (c == v) return v;
    std::string list;
    for (const std::string& c : choices) list += (list.empty() ? "\"" : ", \"") + c + "\"";
    fail("expected one of " + list + ", got " + brief());
}

Vec3d JsonValue::asVec3() const
{
    if (!mValue->is_array() || mValue->size() != 3) fail("expected [x, y, z], got " + brief());
    const std::vector<JsonValue> items = asArray();
    return Vec3d(items[0].asNumber(), items[1].asNumber(), items[2].asNumber());
}

Vec2d JsonValue::asVec2() const
{
    if (!mValue->is_array() || mValue->size() != 2) fail("expected [x, z], got " + brief());
    const std::vector<JsonValue> items = asArray();
    return Vec2d(items[0].asNumber(), items[1].asNumber());
}

std::vector<JsonValue> JsonValue::asArray() const
{
    if (!mValue->is_array()) fail("expected an array, got " + brief());
    std::vector<JsonValue> items;
    for (std::size_t i = 0; i < mValue->size(); ++i) items.push_back(childValue(&(*mValue)[i], std::to_string(i)));
    return items;
}

JsonObject JsonValue::asObject() const { return JsonObject(*this); }

JsonValue JsonValue::childValue(const nlohmann::json* value, const std::string& token) const
{
    return JsonValue(mDocument, value, mFile, child(mPointer, token));
}

JsonObject::JsonObject(const JsonValue& value) : mValue(value)
{
    if (!value.isObject()) value.fail("expected an object {...}, got " + value.brief());
}

bool JsonObject::has(const std::string& key) const { return mValue.raw().contains(key); }

std::optional<JsonValue> JsonObject::find(const std::string& key)
{
    mRead.insert(key);
    const auto it = mValue.raw().find(key);
    if (it == mValue.raw().end()) return std::nullopt;
    return mValue.childValue(&*it, escapePointerToken(key));
}

JsonValue JsonObject::at(const std::string& key)
{
    std::optional<JsonValue> v = find(key);
    if (!v) mValue.fail("missing key \"" + key + "\"");
    return *v;
}

double JsonObject::number(const std::string& key, double fallback)
{
    const std::optional<JsonValue> v = find(key);
    return v ? v->asNumber() : fallback;
}

int JsonObject::integer(const std::string& key, int fallback)
{
    const std::optional<JsonValue> v = find(key);
    return v ? v->asInt() : fallback;
}

int64_t JsonObject::integer64(const std::string& key, int64_t fallback)
{
    const std::optional<JsonValue> v = find(key);
    return v ? v->asInteger(INT64_MIN, INT64_MAX) : fallback;
}

uint64_t JsonObject::unsignedInteger(const std::string& key, uint64_t fallback)
{
    const std::optional<JsonValue> v = find(key);
    return v ? v->asUnsigned() : fallback;
}

bool JsonObject::boolean(const std::string& key, bool fallback)
{
    const std::optional<JsonValue> v = find(key);
    return v ? v->asBool() : fallback;
}

std::string JsonObject::string(const std::string& key, const std::string& fallback)
{
    const std::optional<JsonValue> v = find(key);
    return v ? v->asString() : fallback;
}

std::string JsonObject::choice(const std::string& key, const std::string& fallback, const std::vector<std::string>& choices)
{
    const std::optional<JsonValue> v = find(key);
    return v ? v->asChoice(choices) : fallback;
}

Vec3d JsonObject::vec3(const std::string& key, const Vec3d& fallback)
{
    const std::optional<JsonValue> v = find(key);
    return v ? v->asVec3() : fallback;
}

void JsonObject::finish() const
{
    for (const auto& [key, value] : mValue.raw().items())
        if (mRead.count(key) == 0)
            throw ParseError(mValue.file(), child(mValue.pointer(), escapePointerToken(key)), "unknown key \"" + key + "\"");
}

void validateAt(const JsonValue& json, const std::function<void()>& validate)
{
    try {
        validate();
    } catch (const OptionError& e) {
        const std::string pointer = e.key().empty() ? json.pointer() : child(json.pointer(), e.key());
        throw ParseError(json.file(), pointer, e.detail());
    }
}

namespace {

/// "line L, column C" of the character at a 0-based offset.
std::string lineAndColumn(const std::string& text, std::size_t offset)
{
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i < offset && i < text.size(); ++i) {
        if (text[i] == '\n') {
            ++line;
            column = 1;
        } else {
            ++column;
        }
    }
    return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

/// Refuses a document nested deeper than kMaxJsonDepth before anything is
/// built from it: deep enough nesting overflows the stack of a recursive
/// parser or destructor. Brackets inside strings do not count; syntax is
/// left to the parser.
void checkNesting(const std::string& text, const std::string& file)
{
    int depth = 0;
    bool inString = false, escaped = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (escaped) escaped = false;
            else if (c == '\\') escaped = true;
            else if (c == '"') inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxJsonDepth)
                throw ParseError(file, lineAndColumn(text, i),
                                 "JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " arrays and objects");
        } else if (c == ']' || c == '}') {
            --depth;
        }
    }
}

} // namespace

JsonValue parseJson(const std::string& text, const std::string& file)
{
    checkNesting(text, file);
    auto document = std::make_shared<nlohmann::json>();
    try {
        *document = nlohmann::json::parse(text);
    } catch (const nlohmann::json::parse_error& e) {
        // e.byte is the 1-based offset of the offending character.
        std::string why = e.what();
        const std::size_t colon = why.rfind(": ");
        if (colon != std::string::npos) why = why.substr(colon + 2);
        throw ParseError(file, lineAndColumn(text, e.byte > 0 ? e.byte - 1 : 0), "JSON syntax error: " + why);
    } catch (const nlohmann::json::exception& e) {
        // e.g. a number too large for a double; nlohmann gives no position for these.
        std::string why = e.what();
        const std::size_t bracket = why.find("] ");
        if (bracket != std::string::npos) why = why.substr(bracket + 2);
        throw ParseError(file, "document", "JSON error: " + why);
    }
    const nlohmann::json* root = document.get();
    return JsonValue(std::move(document), root, file, "/");
}

JsonValue readJsonFile(const std::string& path) { return parseJson(readFileBytes(path), path); }

} // namespace vfield
