#pragma once
/// @file math.h
/// The vector types of libvfield: OpenVDB's own (cheap to include), so that
/// meshes and fields pass to OpenVDB tools without conversion.

#include <openvdb/math/BBox.h>
#include <openvdb/math/Mat4.h>
#include <openvdb/math/Vec2.h>
#include <openvdb/math/Vec3.h>

namespace vfield {

using Vec2d = openvdb::math::Vec2d;
using Vec3f = openvdb::math::Vec3s;
using Vec3d = openvdb::math::Vec3d;
using Vec3ui = openvdb::math::Vec3ui;
using BBoxd = openvdb::math::BBox<Vec3d>;
using Mat4d = openvdb::math::Mat4d;

} // namespace vfield
