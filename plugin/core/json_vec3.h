#pragma once
/// @file json_vec3.h
/// A Vec3d as the [x, y, z] array of the files vfield writes and reads back
/// itself (tracks.json, stats.json, a host's scene.json).

#include <vfield/core/math.h>

#include <nlohmann/json.hpp>

namespace vfield {

inline nlohmann::json vec3ToJson(const Vec3d& v) { return {v[0], v[1], v[2]}; }

inline Vec3d vec3FromJson(const nlohmann::json& j)
{
    return Vec3d(j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>());
}

} // namespace vfield
