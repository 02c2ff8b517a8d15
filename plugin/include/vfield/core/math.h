#pragma once
/// @file math.h
/// The vector types of libvfield: OpenVDB's own (cheap to include), so that
/// meshes and fields pass to OpenVDB tools without conversion.

#include <openvdb/math/BBox.h>
#include <openvdb/math/Mat4.h>
#include <openvdb/math/Vec2.h>
#include <openvdb/math/Vec3.h>
#include <openvdb/math/Vec4.h>

namespace vfield {

using Vec2d = openvdb::math::Vec2d;
using Vec3f = openvdb::math::Vec3s;
using Vec3d = openvdb::math::Vec3d;
using Vec3ui = openvdb::math::Vec3ui;
using Vec4d = openvdb::math::Vec4d;
using BBoxd = openvdb::math::BBox<Vec3d>;
using Mat4d = openvdb::math::Mat4d;

/// Corner 0..7 of a box: bit 0 picks max x, bit 1 max y, bit 2 max z.
inline Vec3d boxCorner(const BBoxd& box, int corner)
{
    return Vec3d(corner & 1 ? box.max()[0] : box.min()[0], corner & 2 ? box.max()[1] : box.min()[1],
                 corner & 4 ? box.max()[2] : box.min()[2]);
}

} // namespace vfield
