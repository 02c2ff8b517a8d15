#include <vfield/golden/golden_case.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>
#include <vfield/core/field_visitors.h>
#include <vfield/core/hash.h>
#include <vfield/core/json.h>
#include <vfield/core/vdb_file.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <limits>

namespace fs = std::filesystem;

namespace vfield {

void GoldenGrid::validate() const { checkFields(*this); }

void GoldenThresholds::validate() const { checkFields(*this); }

ImageCompareOptions GoldenThresholds::imageCompareOptions() const
{
    ImageCompareOptions o;
    o.failThreshold = fail;
    o.failPercent = failPercent;
    o.hardFail = hardFail.value_or(std::numeric_limits<double>::infinity());
    o.warnThreshold = warn;
    o.warnPercent = warnPercent;
    o.diffScale = diffScale;
    return o;
}

GoldenThresholds GoldenThresholds::from(const ImageCompareOptions& o)
{
    GoldenThresholds t;
    t.fail = o.failThreshold;
    t.failPercent = o.failPercent;
    if (o.hardFail < std::numeric_limits<double>::infinity()) t.hardFail = o.hardFail;
    t.warn = o.warnThreshold;
    t.warnPercent = o.warnPercent;
    t.diffScale = o.diffScale;
    return t;
}

void GoldenCase::validate() const
{
    checkFields(*this);
    for (std::size_t i = 0; i < commands.size(); ++i)
        require(!commands[i].empty(), "commands/" + std::to_string(i), "expected a vfield command line, got an empty one");
}

namespace {

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
    std::string absolute = fs::absolute(folder).lexically_normal().string();
    if (!absolute.empty() && absolute.back() == '/') absolute.pop_back();
    const std::string caseFile = absolute + "/case.json";
    GoldenCase c = readValidated<GoldenCase>(readJsonFile(caseFile));
    c.folder = absolute;
    return c;
}

void writeGoldenCase(const GoldenCase& c)
{
    writeTextAtomically(c.caseFile(), fieldsToJson<GoldenCase, nlohmann::ordered_json>(c).dump(2) + "\n");
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
