#pragma once
/// @file field_slice.h
/// OctreeField + TriangleMesh (object space) -> a picture of one planar slice,
/// like the paper's figures 1-3: the leaves cut by the plane, shaded by force
/// magnitude (log scale, viridis), outlined; an arrow per leaf showing the
/// in-plane part of its direction; and the mesh's cut in red. Shaded either
/// by each leaf's own force (the paper's field) or, pixel by pixel, by the
/// continuous field particles read by default (FieldSampling::Dual), on the
/// same colour scale.
///
/// The slice is seen from the positive side of its axis, with y up where the
/// axis allows: axis z -> right = +x, up = +y; axis x -> right = -z, up = +y;
/// axis y -> right = +x, up = -z.

#include <vfield/field/octree_field.h>
#include <vfield/field/repulsion_field.h>
#include <vfield/mesh/triangle_mesh.h>

#include <OpenImageIO/imagebuf.h>

namespace vfield {

struct FieldSliceOptions {
    int axis = 2;    ///< normal of the slice plane: 0 x, 1 y, 2 z
    double at = 0.0; ///< plane position along the axis, object units
    /// Edge of the square picture of the root, pixels. 0: large enough that the
    /// finest cells are 12 pixels (within 1024..4096).
    int size = 0;
    /// Nearest: each leaf's own force; Dual: the continuous field at each
    /// pixel (arrows at the leaves' centres). Trilinear is not drawn.
    FieldSampling sampling = FieldSampling::Nearest;
};

/// A 3-channel, display-ready (sRGB) image. Throws ValueError if the plane
/// misses the root or an option is out of range.
OIIO::ImageBuf drawFieldSlice(const OctreeField& field, const TriangleMesh& mesh, const FieldSliceOptions& options);

} // namespace vfield
