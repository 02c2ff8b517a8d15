#include <vfield/field/field_slice.h>

#include <vfield/core/error.h>
#include <vfield/field/field_grid.h>

#include <OpenImageIO/imagebufalgo.h>

#include <openvdb/tools/Interpolation.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace vfield {

namespace {

/// Maps the slice plane to pixels: u to the right, v up.
class SliceProjection {
public:
    SliceProjection(const BBoxd& root, int axis, int size, int border) : mSize(size), mBorder(border)
    {
        // (uAxis, uSign, vAxis, vSign) per slice axis, as documented in the header.
        static constexpr int kPlane[3][4] = {{2, -1, 1, 1}, {0, 1, 2, -1}, {0, 1, 1, 1}};
        mUAxis = kPlane[axis][0];
        mUSign = kPlane[axis][1];
        mVAxis = kPlane[axis][2];
        mVSign = kPlane[axis][3];
        mUStart = mUSign > 0 ? root.min()[mUAxis] : root.max()[mUAxis];
        mVStart = mVSign > 0 ? root.max()[mVAxis] : root.min()[mVAxis];
        mPixelsPerUnit = size / root.extents()[0];
    }

    /// Pixel coordinates (x right, y down) of an object-space point on the plane.
    Vec2d toPixel(const Vec3d& p) const
    {
        return Vec2d(mBorder + mUSign * (p[mUAxis] - mUStart) * mPixelsPerUnit,
                     mBorder + mVSign * (mVStart - p[mVAxis]) * mPixelsPerUnit);
    }
    /// The object-space point on the plane p[axis] = at under a pixel position.
    Vec3d fromPixel(const Vec2d& pixel, int axis, double at) const
    {
        Vec3d p(0.0);
        p[axis] = at;
        p[mUAxis] = mUStart + mUSign * (pixel[0] - mBorder) / mPixelsPerUnit;
        p[mVAxis] = mVStart - mVSign * (pixel[1] - mBorder) / mPixelsPerUnit;
        return p;
    }
    /// A direction's in-plane part, in pixel axes (x right, y down), unscaled.
    Vec2d toPixelDirection(const Vec3d& d) const { return Vec2d(mUSign * d[mUAxis], -mVSign * d[mVAxis]); }
    double pixelsPerUnit() const { return mPixelsPerUnit; }

private:
    int mSize, mBorder;
    int mUAxis, mUSign, mVAxis, mVSign;
    double mUStart, mVStart, mPixelsPerUnit;
};

void drawThickLine(OIIO::ImageBuf& image, Vec2d a, Vec2d b, const float color[3], int thickness)
{
    for (int dx = 0; dx < thickness; ++dx)
        for (int dy = 0; dy < thickness; ++dy)
            OIIO::ImageBufAlgo::render_line(image, int(std::lround(a[0])) + dx, int(std::lround(a[1])) + dy,
                                            int(std::lround(b[0])) + dx, int(std::lround(b[1])) + dy, {color, 3});
}

void drawArrow(OIIO::ImageBuf& image, const Vec2d& center, const Vec2d& direction, double length)
{
    static const float kWhite[3] = {1.0f, 1.0f, 1.0f};
    const double inPlane = direction.length();
    if (inPlane < 0.2) { // the force points mostly through the plane: a dot
        OIIO::ImageBufAlgo::render_box(image, int(center[0]) - 1, int(center[1]) - 1, int(center[0]) + 1, int(center[1]) + 1,
                                       {kWhite, 3}, true);
        return;
    }
    const Vec2d d = direction / inPlane;
    const Vec2d tip = center + d * (0.5 * length * inPlane), tail = center - d * (0.5 * length * inPlane);
    drawThickLine(image, tail, tip, kWhite, 1);
    const double head = std::max(3.0, 0.3 * length * inPlane), c = std::cos(0.45), s = std::sin(0.45);
    const Vec2d left(-d[0] * c + d[1] * s, -d[0] * s - d[1] * c), right(-d[0] * c - d[1] * s, d[0] * s - d[1] * c);
    drawThickLine(image, tip, tip + left * head, kWhite, 1);
    drawThickLine(image, tip, tip + right * head, kWhite, 1);
}

/// The segment where a triangle crosses the plane p[axis] = at, if any.
bool cutTriangle(const Vec3d corners[3], int axis, double at, Vec3d& from, Vec3d& to)
{
    Vec3d hits[3];
    int count = 0;
    for (int i = 0; i < 3 && count < 2; ++i) {
        const Vec3d &a = corners[i], &b = corners[(i + 1) % 3];
        const double da = a[axis] - at, db = b[axis] - at;
        if (da == 0.0) hits[count++] = a;
        else if ((da < 0.0) != (db < 0.0) && db != 0.0) hits[count++] = a + (b - a) * (da / (da - db));
    }
    if (count < 2) return false;
    from = hits[0];
    to = hits[1];
    return true;
}

} // namespace

OIIO::ImageBuf drawFieldSlice(const OctreeField& field, const TriangleMesh& mesh, const FieldSliceOptions& options)
{
    if (options.axis < 0 || options.axis > 2) throw ValueError("slice axis must be x, y or z");
    const BBoxd& root = field.bounds();
    if (!(options.at >= root.min()[options.axis] && options.at <= root.max()[options.axis]))
        throw ValueError("the slice plane at " + std::to_string(options.at) + " misses the field, which spans " +
                         std::to_string(root.min()[options.axis]) + " .. " + std::to_string(root.max()[options.axis]));
    if (options.size != 0 && (options.size < 64 || options.size > 16384))
        throw ValueError("slice size must be within 64..16384 pixels");
    if (options.sampling == FieldSampling::Trilinear) throw ValueError("slices are drawn nearest or dual, not trilinear");

    const int size = options.size != 0 ? options.size : std::clamp(12 << std::min(field.depth() - 1, 12), 1024, 4096);
    const int border = 16;
    const SliceProjection projection(root, options.axis, size, border);
    const int extent = size + 2 * border;

    // The leaves the plane passes through, with the same half-open rule as queries.
    std::vector<FieldLeaf> cut;
    double weakest = std::numeric_limits<double>::max(), strongest = 0.0;
    for (const FieldLeaf& leaf : field.leaves()) {
        const double lo = leaf.bounds.min()[options.axis], hi = leaf.bounds.max()[options.axis];
        const bool onRootMax = hi == root.max()[options.axis];
        if (options.at >= lo && (options.at < hi || (onRootMax && options.at == hi))) {
            cut.push_back(leaf);
            const double m = leaf.force.length();
            if (m > 0) weakest = std::min(weakest, m);
            strongest = std::max(strongest, m);
        }
    }

    // Magnitude on a log scale from the slice's weakest to its strongest cell,
    // through viridis; zero force stays at the dark end.
    const double range = std::log(strongest / weakest);
    const auto shade = [&](double m) {
        return m <= 0 ? 0.0f : range > 0 ? float(std::clamp(0.1 + 0.9 * std::log(m / weakest) / range, 0.0, 1.0)) : 1.0f;
    };
    const OIIO::ImageSpec scalarSpec(extent, extent, 1, OIIO::TypeDesc::FLOAT);
    OIIO::ImageBuf magnitude(scalarSpec);
    OIIO::ImageBufAlgo::zero(magnitude);
    std::vector<std::pair<Vec2d, Vec2d>> boxes; // pixel corners (min, max) per cut leaf
    for (const FieldLeaf& leaf : cut) {
        const Vec2d a = projection.toPixel(leaf.bounds.min()), b = projection.toPixel(leaf.bounds.max());
        const Vec2d lo(std::min(a[0], b[0]), std::min(a[1], b[1])), hi(std::max(a[0], b[0]), std::max(a[1], b[1]));
        boxes.emplace_back(lo, hi);
        const float value = shade(leaf.force.length());
        const OIIO::ROI roi(int(std::lround(lo[0])), int(std::lround(hi[0])), int(std::lround(lo[1])), int(std::lround(hi[1])));
        OIIO::ImageBufAlgo::fill(magnitude, {&value, 1}, roi);
    }
    // The continuous field, read at every pixel's centre, and at the leaves' centres for the arrows.
    std::vector<Vec3d> arrows;
    for (const FieldLeaf& leaf : cut) arrows.push_back(Vec3d(leaf.force));
    if (options.sampling == FieldSampling::Dual) {
        const openvdb::Vec3SGrid::Ptr smooth = smoothForceGrid(field);
        const openvdb::Vec3SGrid::ConstAccessor reads = smooth->getConstAccessor();
        const openvdb::tools::GridSampler<openvdb::Vec3SGrid::ConstAccessor, openvdb::tools::BoxSampler> sampler(
            reads, smooth->transform());
        for (int y = border; y < extent - border; ++y)
            for (int x = border; x < extent - border; ++x) {
                const float value =
                    shade(sampler.wsSample(projection.fromPixel(Vec2d(x + 0.5, y + 0.5), options.axis, options.at)).length());
                magnitude.setpixel(x, y, &value);
            }
        for (std::size_t i = 0; i < cut.size(); ++i) {
            Vec3d centre = cut[i].bounds.getCenter();
            centre[options.axis] = options.at;
            arrows[i] = Vec3d(sampler.wsSample(centre));
        }
    }
    OIIO::ImageBuf image = OIIO::ImageBufAlgo::color_map(magnitude, 0, "viridis");
    if (image.has_error()) throw ValueError("cannot colour the slice: " + image.geterror());
    // Outside the root: neutral dark grey frame.
    const float frame[3] = {0.12f, 0.12f, 0.12f};
    OIIO::ImageBufAlgo::fill(image, {frame, 3}, OIIO::ROI(0, extent, 0, border));
    OIIO::ImageBufAlgo::fill(image, {frame, 3}, OIIO::ROI(0, extent, extent - border, extent));
    OIIO::ImageBufAlgo::fill(image, {frame, 3}, OIIO::ROI(0, border, 0, extent));
    OIIO::ImageBufAlgo::fill(image, {frame, 3}, OIIO::ROI(extent - border, extent, 0, extent));

    // Cell outlines where they are wide enough to read, then arrows.
    static const float kOutline[3] = {0.05f, 0.05f, 0.08f};
    for (std::size_t i = 0; i < cut.size(); ++i) {
        const auto& [lo, hi] = boxes[i];
        const double width = hi[0] - lo[0];
        if (width >= 5.0)
            OIIO::ImageBufAlgo::render_box(image, int(std::lround(lo[0])), int(std::lround(lo[1])), int(std::lround(hi[0])),
                                           int(std::lround(hi[1])), {kOutline, 3});
        if (width >= 10.0 && arrows[i].length() > 0)
            drawArrow(image, (lo + hi) * 0.5, projection.toPixelDirection(arrows[i].unitSafe()), 0.8 * width);
    }

    // The mesh's cut, on top.
    static const float kRed[3] = {0.95f, 0.1f, 0.1f};
    for (const Vec3ui& t : mesh.triangles) {
        const Vec3d corners[3] = {Vec3d(mesh.points[t[0]]), Vec3d(mesh.points[t[1]]), Vec3d(mesh.points[t[2]])};
        Vec3d from, to;
        if (cutTriangle(corners, options.axis, options.at, from, to))
            drawThickLine(image, projection.toPixel(from), projection.toPixel(to), kRed, 2);
    }
    return image;
}

} // namespace vfield
