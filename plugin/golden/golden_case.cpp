#include <vfield/golden/golden_case.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>
#include <vfield/core/hash.h>
#include <vfield/core/json.h>
#include <vfield/core/vdb_file.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <limits>

namespace fs = std::filesystem;

namespace vfield {

namespace {

std::vector<std::string> readStrings(const JsonValue& array)
{
    std::vector<std::string> strings;
    for (const JsonValue& item : array.asArray()) strings.push_back(item.asString());
    return strings;
}

enum class Bound { None, Percent };

/// A threshold >= 0 (a percentage: <= 100 too), or fallback when the key is missing.
double readThreshold(JsonObject& object, const std::string& key, double fallback, Bound bound = Bound::None)
{
    const std::optional<JsonValue> value = object.find(key);
    if (!value) return fallback;
    const double x = value->asNumber();
    if (x < 0.0 || (bound == Bound::Percent && x > 100.0))
        value->fail(std::string(bound == Bound::Percent ? "expected a percentage within [0, 100]" : "expected a number >= 0") +
                    ", got " + value->brief());
    return x;
}

ImageCompareOptions readThresholds(const JsonValue& json)
{
    JsonObject object(json);
    ImageCompareOptions o;
    o.failThreshold = readThreshold(object, "fail", o.failThreshold);
    o.failPercent = readThreshold(object, "failPercent", o.failPercent, Bound::Percent);
    o.hardFail = readThreshold(object, "hardFail", o.hardFail);
    o.warnThreshold = readThreshold(object, "warn", o.warnThreshold);
    o.warnPercent = readThreshold(object, "warnPercent", o.warnPercent, Bound::Percent);
    o.diffScale = readThreshold(object, "diffScale", o.diffScale);
    if (o.diffScale == 0.0) object.at("diffScale").fail("expected a number > 0");
    object.finish();
    return o;
}

GoldenRegeneration readRegeneration(const JsonValue& json)
{
    JsonObject object(json);
    GoldenRegeneration r;
    r.date = object.at("date").asString();
    r.reason = object.at("reason").asString();
    if (auto differences = object.find("differences")) r.differences = readStrings(*differences);
    object.finish();
    return r;
}

std::string replaceAll(std::string text, const std::string& from, const std::string& to)
{
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
        text.replace(at, from.size(), to);
    return text;
}

} // namespace

std::string GoldenCase::scenePath() const
{
    return scene.empty() ? std::string() : (fs::path(folder) / scene).lexically_normal().string();
}

std::string GoldenCase::goldenPath(const std::string& output) const
{
    return folder + "/" + fs::path(output).filename().string();
}

std::vector<std::vector<std::string>> GoldenCase::commandsFor(const std::string& outDir) const
{
    std::vector<std::vector<std::string>> result;
    for (const std::vector<std::string>& command : commands) {
        std::vector<std::string>& arguments = result.emplace_back();
        for (const std::string& argument : command)
            arguments.push_back(
                replaceAll(replaceAll(replaceAll(argument, "@SCENE@", scenePath()), "@OUT@", outDir), "@CASE@", folder));
    }
    return result;
}

GoldenCase readGoldenCase(const std::string& folder)
{
    GoldenCase c;
    c.folder = fs::absolute(folder).lexically_normal().string();
    if (!c.folder.empty() && c.folder.back() == '/') c.folder.pop_back();
    JsonObject root(readJsonFile(c.caseFile()));
    c.why = root.string("why", "");
    c.scene = root.string("scene", "");
    c.sceneHash = root.string("sceneHash", "");
    for (const JsonValue& command : root.at("commands").asArray()) {
        c.commands.push_back(readStrings(command));
        if (c.commands.back().empty()) command.fail("expected a vfield command line, got an empty one");
    }
    c.images = readStrings(root.at("images"));
    if (auto grids = root.find("grids"))
        for (const JsonValue& item : grids->asArray()) {
            JsonObject grid(item);
            GoldenGrid g;
            g.file = grid.at("file").asString();
            g.checksum = grid.string("checksum", "");
            g.keepFile = grid.boolean("keepFile", false);
            g.tolerance = grid.number("tolerance", 0.0);
            if (g.tolerance < 0.0) grid.at("tolerance").fail("expected a number >= 0");
            grid.finish();
            c.grids.push_back(g);
        }
    c.compare = readThresholds(root.at("compare"));
    if (auto regenerated = root.find("regenerated"))
        for (const JsonValue& item : regenerated->asArray()) c.regenerated.push_back(readRegeneration(item));
    root.finish();
    return c;
}

void writeGoldenCase(const GoldenCase& c)
{
    nlohmann::ordered_json root;
    root["why"] = c.why;
    if (!c.scene.empty()) {
        root["scene"] = c.scene;
        root["sceneHash"] = c.sceneHash;
    }
    root["commands"] = c.commands;
    root["images"] = c.images;
    if (!c.grids.empty()) {
        root["grids"] = nlohmann::ordered_json::array();
        for (const GoldenGrid& g : c.grids)
            root["grids"].push_back(
                {{"file", g.file}, {"checksum", g.checksum}, {"keepFile", g.keepFile}, {"tolerance", g.tolerance}});
    }
    nlohmann::ordered_json& compare = root["compare"];
    compare["fail"] = c.compare.failThreshold;
    compare["failPercent"] = c.compare.failPercent;
    if (c.compare.hardFail < std::numeric_limits<double>::infinity()) compare["hardFail"] = c.compare.hardFail;
    compare["warn"] = c.compare.warnThreshold;
    compare["warnPercent"] = c.compare.warnPercent;
    compare["diffScale"] = c.compare.diffScale;
    if (!c.regenerated.empty()) {
        root["regenerated"] = nlohmann::ordered_json::array();
        for (const GoldenRegeneration& r : c.regenerated) {
            nlohmann::ordered_json entry = {{"date", r.date}, {"reason", r.reason}};
            if (!r.differences.empty()) entry["differences"] = r.differences;
            root["regenerated"].push_back(entry);
        }
    }
    writeTextAtomically(c.caseFile(), root.dump(2) + "\n");
}

std::vector<GoldenCaseRef> findGoldenCases(const std::string& root)
{
    std::error_code error;
    if (!fs::is_directory(root, error)) throw FileError(root, "no such folder");
    const fs::path base = fs::absolute(root).lexically_normal();
    if (fs::exists(base / "case.json")) {
        const fs::path name = base.has_filename() ? base.filename() : base.parent_path().filename();
        return {{name.string(), base.string()}};
    }
    std::vector<GoldenCaseRef> cases;
    for (const fs::directory_entry& entry : fs::recursive_directory_iterator(base))
        if (entry.is_regular_file() && entry.path().filename() == "case.json") {
            const fs::path folder = entry.path().parent_path();
            cases.push_back({folder.lexically_relative(base).string(), folder.string()});
        }
    if (cases.empty()) throw FileError(root, "holds no golden case (no case.json in it or below it)");
    std::sort(cases.begin(), cases.end(), [](const GoldenCaseRef& a, const GoldenCaseRef& b) { return a.name < b.name; });
    return cases;
}

std::string fileContentHash(const std::string& path)
{
    ContentHash hash;
    hash.add(readFileBytes(path));
    return hashText(hash.value());
}

std::string vdbFileChecksum(const std::string& path)
{
    ContentHash hash;
    for (const openvdb::GridBase::Ptr& grid : readVdb(path)) hash.addValue(gridChecksum(*grid));
    return hashText(hash.value());
}

} // namespace vfield
