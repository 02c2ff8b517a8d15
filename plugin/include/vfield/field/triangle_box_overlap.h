#pragma once
/// @file triangle_box_overlap.h
/// Exact overlap of a triangle and a closed axis-aligned box, by the separating
/// axis theorem (Akenine-Moller, "Fast 3D triangle-box overlap testing", 2001):
/// the 3 box normals, the triangle normal and the 9 edge cross products.
/// Touching counts as overlapping, so a triangle on a face lies in both boxes.

#include <vfield/core/math.h>

namespace vfield {

bool triangleOverlapsBox(const Vec3d& boxCenter, const Vec3d& boxHalfSize, const Vec3d& a, const Vec3d& b, const Vec3d& c);

} // namespace vfield
