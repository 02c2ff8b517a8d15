#pragma once
/// @file tracks.h
/// tracks.json: per dynamic object, its pose and velocity at every frame
/// simulated, and the queries renderers and hosts make of it (a pose at a
/// frame, the path a following camera rides).

#include <vfield/core/transform.h>
#include <vfield/sim/simulator.h>

#include <map>
#include <string>
#include <vector>

namespace vfield {

/// One dynamic object's state at one frame, as tracks.json holds it.
struct TrackEntry {
    int frame = 0;
    Transform pose;      ///< position (the pivot, world) and orientation; scale is the scene's
    Vec3d velocity{0.0}; ///< world units / s
};

/// Per dynamic object (by name), its track over the frames simulated.
class Tracks {
public:
    void add(const std::string& object, int frame, const DynamicState& state);
    /// Drops every entry after frame.
    void keepUpTo(int frame);
    const std::map<std::string, std::vector<TrackEntry>>& objects() const { return mObjects; }
    /// The object's entry at frame. Throws FileError (naming the file it was
    /// read from) when the track holds no such entry.
    const TrackEntry& at(const std::string& object, int frame) const;
    /// Does the track hold the object's entry at frame?
    bool holds(const std::string& object, int frame) const { return find(object, frame) != nullptr; }
    /// The object's pose at frame; throws as at() does.
    Transform pose(const std::string& object, int frame) const { return at(object, frame).pose; }
    /// The object's poses from the first frame of its track through frame, in
    /// frame order: the path a following camera rides. Throws as pose() does.
    std::vector<Transform> path(const std::string& object, int frame) const;
    /// The pose at a fractional frame (a shutter's open or close), between
    /// the entries of the frames around it by interpolate(); where the track
    /// holds only one of them (before its first frame, after its last), that
    /// one's pose. Throws as at() does when it holds neither.
    Transform poseAt(const std::string& object, double frame) const;
    /// The path through the frame before a fractional frame, ending at its
    /// poseAt(): what a following camera rides to it.
    std::vector<Transform> pathTo(const std::string& object, double frame) const;

    /// tracks.json's text; fps is recorded beside the tracks, with the convention they follow.
    std::string toJsonText(double fps) const;
    /// Reads tracks.json text (path names it in errors). Throws FileError.
    static Tracks fromJsonText(const std::string& text, const std::string& path);
    /// The tracks alone, as a run state keeps them.
    std::string objectsJsonText() const;
    static Tracks fromObjectsJsonText(const std::string& text, const std::string& path);

private:
    const TrackEntry* find(const std::string& object, int frame) const; ///< null when there is none
    std::string mPath;                                                  ///< where it was read from, for messages
    std::map<std::string, std::vector<TrackEntry>> mObjects;
};

} // namespace vfield
