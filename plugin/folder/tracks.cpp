#include <vfield/folder/tracks.h>

#include "../core/json_vec3.h"

#include <vfield/core/error.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <iterator>

namespace vfield {

namespace {

nlohmann::json objectsToJson(const std::map<std::string, std::vector<TrackEntry>>& objects)
{
    nlohmann::json json = nlohmann::json::object();
    for (const auto& [name, entries] : objects) {
        nlohmann::json& track = json[name];
        for (const TrackEntry& e : entries) {
            const Quatd& q = e.pose.rotation;
            // Transform::matrix() multiplies row vectors (OpenVDB's way); the
            // file states the column-vector form that most hosts take.
            const Mat4d m = e.pose.matrix();
            nlohmann::json matrix = nlohmann::json::array();
            for (int row = 0; row < 4; ++row)
                for (int col = 0; col < 4; ++col) matrix.push_back(m(col, row));
            track.push_back({{"frame", e.frame},
                             {"position", vec3ToJson(e.pose.translation)},
                             {"orientation", {q.x(), q.y(), q.z(), q.w()}},
                             {"scale", e.pose.scale},
                             {"matrix", matrix},
                             {"velocity", vec3ToJson(e.velocity)}});
        }
    }
    return json;
}

std::map<std::string, std::vector<TrackEntry>> objectsFromJson(const nlohmann::json& json)
{
    std::map<std::string, std::vector<TrackEntry>> objects;
    for (const auto& [name, entries] : json.items())
        for (const nlohmann::json& e : entries) {
            TrackEntry entry;
            entry.frame = e.at("frame").get<int>();
            const auto q = e.at("orientation").get<std::vector<double>>();
            entry.pose.translation = vec3FromJson(e.at("position"));
            entry.pose.rotation = Quatd(q.at(0), q.at(1), q.at(2), q.at(3));
            entry.pose.scale = e.at("scale").get<double>();
            entry.velocity = vec3FromJson(e.at("velocity"));
            objects[name].push_back(entry);
        }
    return objects;
}

constexpr const char* kTracksConvention =
    "object-to-world transform of the mesh that export-mesh writes in object space: world = position + "
    "orientation * (scale * p); position: the object's pivot (its mesh's origin) in world space; orientation: "
    "unit quaternion [x, y, z, w] rotating object space (nose +x, up +y) into world space; scale: uniform; "
    "matrix: the same transform as a 4x4 matrix, 16 numbers row by row, for column vectors "
    "(world = M [x, y, z, 1]^T, translation in the last column); velocity: world units per second";

} // namespace

void Tracks::add(const std::string& object, int frame, const DynamicState& state)
{
    mObjects[object].push_back({frame, state.pose, state.velocity});
}

void Tracks::keepUpTo(int frame)
{
    for (auto& [name, entries] : mObjects)
        entries.erase(std::remove_if(entries.begin(), entries.end(), [frame](const TrackEntry& e) { return e.frame > frame; }),
                      entries.end());
}

const TrackEntry* Tracks::find(const std::string& object, int frame) const
{
    const auto o = mObjects.find(object);
    if (o != mObjects.end())
        for (const TrackEntry& e : o->second)
            if (e.frame == frame) return &e;
    return nullptr;
}

const TrackEntry& Tracks::at(const std::string& object, int frame) const
{
    if (const TrackEntry* entry = find(object, frame)) return *entry;
    throw FileError(mPath, "no pose of \"" + object + "\" at frame " + std::to_string(frame));
}

Transform Tracks::poseAt(const std::string& object, double frame) const
{
    const int before = int(std::floor(frame));
    if (frame == before) return pose(object, before);
    const TrackEntry *a = find(object, before), *b = find(object, before + 1);
    if (a && b) return interpolate(a->pose, b->pose, frame - before);
    if (a || b) return (a ? a : b)->pose;
    return pose(object, before); // throws, naming the frame
}

std::vector<Transform> Tracks::pathTo(const std::string& object, double frame) const
{
    const int before = int(std::floor(frame));
    if (frame == before) return path(object, before);
    if (!find(object, before)) return path(object, before + 1); // before the track's start: held there
    std::vector<Transform> poses = path(object, before);
    if (find(object, before + 1)) poses.push_back(poseAt(object, frame));
    return poses;
}

std::vector<Transform> Tracks::path(const std::string& object, int frame) const
{
    std::vector<TrackEntry> entries;
    if (const auto o = mObjects.find(object); o != mObjects.end())
        std::copy_if(o->second.begin(), o->second.end(), std::back_inserter(entries),
                     [frame](const TrackEntry& e) { return e.frame <= frame; });
    std::sort(entries.begin(), entries.end(), [](const TrackEntry& a, const TrackEntry& b) { return a.frame < b.frame; });
    if (entries.empty() || entries.back().frame != frame)
        throw FileError(mPath, "no pose of \"" + object + "\" at frame " + std::to_string(frame));
    std::vector<Transform> poses;
    for (const TrackEntry& e : entries) poses.push_back(e.pose);
    return poses;
}

std::string Tracks::toJsonText(double fps) const
{
    const nlohmann::json json = {{"fps", fps}, {"convention", kTracksConvention}, {"objects", objectsToJson(mObjects)}};
    return json.dump(1) + "\n";
}

std::string Tracks::objectsJsonText() const { return objectsToJson(mObjects).dump(); }

Tracks Tracks::fromObjectsJsonText(const std::string& text, const std::string& path)
{
    Tracks tracks;
    tracks.mPath = path;
    try {
        tracks.mObjects = objectsFromJson(nlohmann::json::parse(text));
    } catch (const nlohmann::json::exception& e) {
        throw FileError(path, std::string("unreadable tracks: ") + e.what());
    }
    return tracks;
}

Tracks Tracks::fromJsonText(const std::string& text, const std::string& path)
{
    Tracks tracks;
    tracks.mPath = path;
    try {
        tracks.mObjects = objectsFromJson(nlohmann::json::parse(text).at("objects"));
    } catch (const nlohmann::json::exception& e) {
        throw FileError(path, std::string("unreadable tracks: ") + e.what());
    }
    return tracks;
}

} // namespace vfield
