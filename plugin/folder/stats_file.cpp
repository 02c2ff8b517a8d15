#include <vfield/folder/stats_file.h>

#include "../core/json_vec3.h"

#include <vfield/core/error.h>
#include <vfield/core/hash.h>

#include <nlohmann/json.hpp>

namespace vfield {

namespace {

nlohmann::json toJson(const ClearanceStats& c)
{
    if (c.samples == 0) return nullptr;
    return {
        {"min", c.minimum}, {"p01", c.percentile1}, {"mean", c.mean}, {"penetrations", c.penetrations}, {"samples", c.samples}};
}

ClearanceStats clearanceFromJson(const nlohmann::json& j)
{
    ClearanceStats c;
    if (j.is_null()) return c;
    c.minimum = j.at("min").get<double>();
    c.percentile1 = j.at("p01").get<double>();
    c.mean = j.value("mean", 0.0); // absent from runs saved before it was measured
    c.penetrations = j.at("penetrations").get<uint64_t>();
    c.samples = j.at("samples").get<uint64_t>();
    return c;
}

/// 64-bit hashes as 16 hexadecimal digits: JSON numbers lose their low bits in many readers.
uint64_t hexValue(const nlohmann::json& j) { return std::stoull(j.get<std::string>(), nullptr, 16); }

nlohmann::json toJson(const FileFingerprint& f) { return {{"bytes", f.bytes}, {"hash", hashText(f.hash)}}; }
FileFingerprint fingerprintFromJson(const nlohmann::json& j) { return {j.at("bytes").get<uint64_t>(), hexValue(j.at("hash"))}; }

nlohmann::json toJson(const FrameRecord& r)
{
    const bool any = r.alive > 0;
    nlohmann::json pairs = nlohmann::json::array();
    for (const PairClearance& pair : r.objectPairs)
        pairs.push_back({{"objects", {pair.first, pair.second}}, {"min", pair.minimum}, {"exact", pair.exact}});
    return {{"frame", r.frame},
            {"centroid", any ? vec3ToJson(r.centroid) : nlohmann::json(nullptr)},
            {"boundsMin", any ? vec3ToJson(r.bounds.min()) : nlohmann::json(nullptr)},
            {"boundsMax", any ? vec3ToJson(r.bounds.max()) : nlohmann::json(nullptr)},
            {"alive", r.alive},
            {"removed", r.removed},
            {"substeps", r.substeps},
            {"maxSubsteps", r.maxSubsteps},
            {"dynamicSubsteps", r.dynamicSubsteps},
            {"contacts", r.contacts},
            {"endedInside", r.endedInside},
            {"maxRollChangeDegrees", r.maxRollChange},
            {"seconds", r.seconds},
            {"stageSeconds",
             {{"advection", r.stages.advection},
              {"clearance", r.stages.clearance},
              {"splat", r.stages.splat},
              {"detail", r.stages.detail},
              {"write", r.stages.write}}},
            {"clearance", {{"particles", toJson(r.particleClearance)}, {"objects", pairs}}},
            {"files", r.files ? nlohmann::json{{"density", toJson(r.files->density)}, {"particles", toJson(r.files->particles)}}
                              : nlohmann::json(nullptr)}};
}

FrameRecord recordFromJson(const nlohmann::json& j)
{
    FrameRecord r;
    r.frame = j.at("frame").get<int>();
    r.alive = j.at("alive").get<uint64_t>();
    r.removed = j.at("removed").get<uint64_t>();
    r.substeps = j.at("substeps").get<uint64_t>();
    r.maxSubsteps = j.at("maxSubsteps").get<uint32_t>();
    r.dynamicSubsteps = j.at("dynamicSubsteps").get<uint32_t>();
    r.contacts = j.at("contacts").get<uint64_t>();
    r.endedInside = j.value("endedInside", uint64_t(0));
    r.maxRollChange = j.at("maxRollChangeDegrees").get<double>();
    r.seconds = j.value("seconds", 0.0);
    if (const auto stages = j.find("stageSeconds"); stages != j.end())
        r.stages = {stages->value("advection", 0.0), stages->value("clearance", 0.0), stages->value("splat", 0.0),
                    stages->value("detail", 0.0), stages->value("write", 0.0)};
    if (!j.at("centroid").is_null()) {
        r.centroid = vec3FromJson(j.at("centroid"));
        r.bounds = BBoxd(vec3FromJson(j.at("boundsMin")), vec3FromJson(j.at("boundsMax")));
    }
    r.particleClearance = clearanceFromJson(j.at("clearance").at("particles"));
    if (const auto files = j.find("files"); files != j.end() && !files->is_null())
        r.files = FrameFiles{fingerprintFromJson(files->at("density")), fingerprintFromJson(files->at("particles"))};
    for (const nlohmann::json& pair : j.at("clearance").at("objects"))
        r.objectPairs.push_back({pair.at("objects").at(0).get<std::string>(), pair.at("objects").at(1).get<std::string>(),
                                 pair.at("min").get<double>(), pair.value("exact", true)});
    return r;
}

nlohmann::json recordsToJson(const std::vector<FrameRecord>& records)
{
    nlohmann::json array = nlohmann::json::array();
    for (const FrameRecord& r : records) array.push_back(toJson(r));
    return array;
}

std::vector<FrameRecord> recordsFromJson(const nlohmann::json& array)
{
    std::vector<FrameRecord> records;
    for (const nlohmann::json& r : array) records.push_back(recordFromJson(r));
    return records;
}

} // namespace

std::string statsJsonText(const StatsFile& stats)
{
    nlohmann::json fields = nlohmann::json::array();
    for (const FieldRecord& f : stats.fields)
        fields.push_back({{"object", f.object},
                          {"method", f.method},
                          {"buildSeconds", f.buildSeconds},
                          {"memoryBytes", f.memoryBytes},
                          {"finestCell", f.finestCell}});
    const nlohmann::json json = {{"inputsHash", hashText(stats.inputsHash)},
                                 {"fps", stats.fps},
                                 {"fields", fields},
                                 {"frames", recordsToJson(stats.frames)}};
    return json.dump(1) + "\n";
}

StatsFile statsFromJsonText(const std::string& text, const std::string& path)
{
    try {
        const nlohmann::json json = nlohmann::json::parse(text);
        StatsFile stats;
        stats.fps = json.at("fps").get<double>();
        if (json.contains("inputsHash")) stats.inputsHash = hexValue(json.at("inputsHash"));
        for (const nlohmann::json& f : json.at("fields"))
            stats.fields.push_back({f.at("object").get<std::string>(), f.at("method").get<std::string>(),
                                    f.at("buildSeconds").get<double>(), f.at("memoryBytes").get<uint64_t>(),
                                    f.at("finestCell").get<double>()});
        stats.frames = recordsFromJson(json.at("frames"));
        return stats;
    } catch (const nlohmann::json::exception& e) {
        throw FileError(path, std::string("unreadable statistics: ") + e.what());
    } catch (const std::logic_error& e) { // a hash that is not hexadecimal
        throw FileError(path, std::string("unreadable statistics: ") + e.what());
    }
}

std::string frameRecordsJsonText(const std::vector<FrameRecord>& records) { return recordsToJson(records).dump(); }

std::vector<FrameRecord> frameRecordsFromJsonText(const std::string& text, const std::string& path)
{
    try {
        return recordsFromJson(nlohmann::json::parse(text));
    } catch (const nlohmann::json::exception& e) {
        throw FileError(path, std::string("unreadable frame records: ") + e.what());
    } catch (const std::logic_error& e) {
        throw FileError(path, std::string("unreadable frame records: ") + e.what());
    }
}

} // namespace vfield
