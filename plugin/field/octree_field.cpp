#include <vfield/field/octree_field.h>

#include <vfield/core/error.h>
#include <vfield/core/field_visitors.h>
#include <vfield/field/triangle_box_overlap.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <string>

namespace vfield {

void OctreeFieldSettings::validate() const { checkFields(*this); }

double magnitudeAtLevel(MagnitudeGrowth growth, double strength, double level)
{
    return growth == MagnitudeGrowth::Linear ? strength * level : strength * std::exp2(level - 1.0);
}

double OctreeField::cellSize(int level) const { return mCellSize[level]; }

/// The coordinate of the index-th cell boundary at level along axis. Building
/// and querying both place boundaries through this one function, so a point on
/// a boundary falls on the same side for both. Boundaries are measured from the
/// root's centre, which makes the central planes exact: a flat mesh, which
/// always lies on one of them, touches the octants on both sides.
double OctreeField::boundary(int axis, uint32_t index, int level) const
{
    return mCenter[axis] + (double(index) - mCentralIndex[level]) * mCellSize[level];
}

double OctreeField::magnitude(int level, bool isSurface) const
{
    return magnitudeAtLevel(mSettings.growth, mSettings.strength, level) * (isSurface ? mSettings.surfaceBoost : 1.0);
}

Vec3f OctreeField::forceOf(const Node& node) const { return node.direction * float(magnitude(node.level, node.isSurface)); }

namespace {

/// A triangle as the builder needs it: corners and unit normal in double precision.
struct BuildTriangle {
    Vec3d a, b, c;
    Vec3d normal;
};

constexpr double kZeroAverage = 1e-9;
/// Boxes are closed: a triangle lying on a cell boundary belongs to the cells on
/// both sides. The exact test is done on boxes grown by this fraction of their
/// size, so that rounding of the box's centre cannot turn touching into missing.
constexpr double kTouchTolerance = 1e-9;
/// Nodes with at least this many triangles build their octants in parallel.
constexpr std::size_t kParallelTriangles = 4096;

class OctreeBuilder {
public:
    OctreeBuilder(std::vector<BuildTriangle> triangles, const OctreeFieldSettings& options,
                  const std::function<double(int, uint32_t, int)>& boundary)
        : mTriangles(std::move(triangles)), mSettings(options), mBoundary(boundary)
    {}

    /// Fills out[index] for the node at `cell` of `level` holding `inside`, and
    /// appends its descendants to out.
    void build(std::vector<OctreeField::Node>& out, uint32_t index, const uint32_t cell[3], int level,
               std::vector<uint32_t>& inside, const Vec3f& parentDirection)
    {
        Vec3d sum(0.0);
        for (uint32_t t : inside) sum += mTriangles[t].normal;
        Vec3f direction = parentDirection;
        if (!inside.empty()) {
            const Vec3d average = sum / double(inside.size());
            if (average.length() >= kZeroAverage) direction = Vec3f(average.unitSafe());
        }
        const bool split = (inside.size() > std::size_t(mSettings.maxPerLeaf) ||
                            (mSettings.splitRule == SplitRule::NormalCone && normalsOppose(inside))) &&
                           level < mSettings.maxLevel;

        OctreeField::Node node;
        node.level = uint8_t(level);
        node.direction = direction; // interior nodes' too: the smooth field reads them (field_grid.h)
        if (!split) {
            node.isSurface = !inside.empty();
            out[index] = node;
            int deepest = mDepth.load();
            while (level > deepest && !mDepth.compare_exchange_weak(deepest, level)) {}
            return;
        }

        std::vector<uint32_t> octantTriangles[8];
        uint32_t childCells[8][3];
        distribute(cell, level, inside, octantTriangles, childCells);
        const bool parallel = inside.size() >= kParallelTriangles;
        std::vector<uint32_t>().swap(inside); // release before descending

        node.firstChild = uint32_t(out.size());
        out[index] = node;
        out.resize(out.size() + 8);
        if (!parallel) {
            for (int octant = 0; octant < 8; ++octant)
                build(out, node.firstChild + octant, childCells[octant], level + 1, octantTriangles[octant], direction);
            return;
        }
        // Octants are built into their own arrays at once, then spliced in
        // order, so the layout is the same for any number of threads.
        std::vector<OctreeField::Node> subtrees[8];
        tbb::parallel_for(0, 8, [&](int octant) {
            subtrees[octant].resize(1);
            build(subtrees[octant], 0, childCells[octant], level + 1, octantTriangles[octant], direction);
        });
        for (int octant = 0; octant < 8; ++octant) splice(out, node.firstChild + octant, subtrees[octant]);
    }

    int depth() const { return mDepth.load(); }

private:
    /// Whether two of the node's triangles face more than 90 degrees apart
    /// (the two sides of a thin part, a fold), so that their average would
    /// point along the part rather than away from either side. Asked only of
    /// nodes the count rule would keep, at most maxPerLeaf triangles: the
    /// pairwise test stays cheap.
    bool normalsOppose(const std::vector<uint32_t>& inside) const
    {
        for (std::size_t i = 0; i < inside.size(); ++i)
            for (std::size_t j = i + 1; j < inside.size(); ++j)
                if (mTriangles[inside[i]].normal.dot(mTriangles[inside[j]].normal) < 0.0) return true;
        return false;
    }

    /// Sorts the node's triangles into the octants whose closed boxes they overlap.
    void distribute(const uint32_t cell[3], int level, const std::vector<uint32_t>& inside,
                    std::vector<uint32_t> octantTriangles[8], uint32_t childCells[8][3]) const
    {
        const int childLevel = level + 1;
        double lo[3], mid[3], hi[3];
        for (int axis = 0; axis < 3; ++axis) {
            lo[axis] = mBoundary(axis, 2 * cell[axis], childLevel);
            mid[axis] = mBoundary(axis, 2 * cell[axis] + 1, childLevel);
            hi[axis] = mBoundary(axis, 2 * cell[axis] + 2, childLevel);
        }
        Vec3d centers[8], halfSizes[8];
        for (int octant = 0; octant < 8; ++octant) {
            for (int axis = 0; axis < 3; ++axis) {
                const bool upper = (octant >> axis) & 1;
                const double min = upper ? mid[axis] : lo[axis], max = upper ? hi[axis] : mid[axis];
                centers[octant][axis] = 0.5 * (min + max);
                halfSizes[octant][axis] = 0.5 * (max - min) * (1.0 + kTouchTolerance);
                childCells[octant][axis] = 2 * cell[axis] + (upper ? 1 : 0);
            }
            octantTriangles[octant].reserve(inside.size() / 4 + 1);
        }

        for (uint32_t t : inside) {
            const BuildTriangle& tri = mTriangles[t];
            // Which halves each axis' extent of the triangle reaches, and whether
            // it lies within one half entirely (then no exact test is needed).
            int halves[3];
            bool contained = true;
            for (int axis = 0; axis < 3; ++axis) {
                const double tmin = std::min({tri.a[axis], tri.b[axis], tri.c[axis]});
                const double tmax = std::max({tri.a[axis], tri.b[axis], tri.c[axis]});
                const bool lower = tmin <= mid[axis] && tmax >= lo[axis];
                const bool upper = tmax >= mid[axis] && tmin <= hi[axis];
                halves[axis] = (lower ? 1 : 0) | (upper ? 2 : 0);
                contained = contained && (halves[axis] != 3) && tmin >= lo[axis] && tmax <= hi[axis];
            }
            for (int octant = 0; octant < 8; ++octant) {
                bool reaches = true;
                for (int axis = 0; axis < 3 && reaches; ++axis) reaches = halves[axis] & (1 << ((octant >> axis) & 1));
                if (!reaches) continue;
                if (contained || triangleOverlapsBox(centers[octant], halfSizes[octant], tri.a, tri.b, tri.c))
                    octantTriangles[octant].push_back(t);
            }
        }
    }

    /// Moves a subtree built on its own (root at sub[0]) into out: its root to
    /// out[index], its other nodes appended, child indices rebased.
    static void splice(std::vector<OctreeField::Node>& out, uint32_t index, std::vector<OctreeField::Node>& sub)
    {
        const auto base = uint32_t(out.size());
        const auto rebase = [base](OctreeField::Node node) {
            if (node.firstChild != 0) node.firstChild = base + node.firstChild - 1;
            return node;
        };
        out[index] = rebase(sub[0]);
        out.reserve(out.size() + sub.size() - 1);
        for (std::size_t i = 1; i < sub.size(); ++i) out.push_back(rebase(sub[i]));
        std::vector<OctreeField::Node>().swap(sub);
    }

    std::vector<BuildTriangle> mTriangles;
    const OctreeFieldSettings& mSettings;
    std::function<double(int, uint32_t, int)> mBoundary;
    std::atomic<int> mDepth{1};
};

} // namespace

OctreeField OctreeField::build(const TriangleMesh& mesh, const OctreeFieldSettings& options)
{
    options.validate();

    std::vector<BuildTriangle> triangles;
    triangles.reserve(mesh.triangles.size());
    BBoxd box;
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
        const Vec3d area = mesh.areaVector(i);
        if (!(area.lengthSqr() > 0.0)) continue; // zero-area triangles have no normal
        const Vec3ui& t = mesh.triangles[i];
        const Vec3d normal = options.flipNormals ? -area.unitSafe() : area.unitSafe();
        BuildTriangle tri{Vec3d(mesh.points[t[0]]), Vec3d(mesh.points[t[1]]), Vec3d(mesh.points[t[2]]), normal};
        box.expand(tri.a);
        box.expand(tri.b);
        box.expand(tri.c);
        triangles.push_back(tri);
    }
    if (triangles.empty()) throw ValueError("the mesh has no triangle of non-zero area to build a field around");
    for (int axis = 0; axis < 3; ++axis)
        if (!std::isfinite(box.min()[axis]) || !std::isfinite(box.max()[axis]))
            throw ValueError("the mesh has non-finite coordinates");

    OctreeField field;
    field.mSettings = options;
    const double largestExtent = box.extents()[box.maxExtent()];
    const double margin = options.margin.value_or(0.1 * largestExtent);
    const double side = largestExtent + 2.0 * margin;
    field.mCenter = box.getCenter();
    field.mSide = side;
    for (int level = 1; level <= kMaxLevels; ++level) {
        field.mCellSize[level] = std::ldexp(side, 1 - level);
        field.mCentralIndex[level] = std::ldexp(1.0, level - 2); // half of the level's 2^(level-1) cells
    }
    field.mBounds = BBoxd(field.mCenter - Vec3d(0.5 * side), field.mCenter + Vec3d(0.5 * side));

    std::vector<uint32_t> all(triangles.size());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = uint32_t(i);
    OctreeBuilder builder(std::move(triangles), field.mSettings,
                          [&field](int axis, uint32_t index, int level) { return field.boundary(axis, index, level); });
    field.mNodes.resize(1);
    const uint32_t rootCell[3] = {0, 0, 0};
    builder.build(field.mNodes, 0, rootCell, 1, all, Vec3f(0.0f));
    field.mNodes.shrink_to_fit();
    field.mDepth = builder.depth();
    field.mLeafCount =
        std::size_t(std::count_if(field.mNodes.begin(), field.mNodes.end(), [](const Node& n) { return n.firstChild == 0; }));
    return field;
}

FieldSample OctreeField::sample(const Vec3d& p) const
{
    if (!mBounds.isInside(p)) return {}; // BBox::isInside is closed, and false for NaN
    uint32_t index = 0, cell[3] = {0, 0, 0};
    int level = 1;
    while (mNodes[index].firstChild != 0) {
        int octant = 0;
        for (int axis = 0; axis < 3; ++axis) {
            const uint32_t upper = p[axis] >= boundary(axis, 2 * cell[axis] + 1, level + 1) ? 1 : 0;
            cell[axis] = 2 * cell[axis] + upper;
            octant |= int(upper) << axis;
        }
        index = mNodes[index].firstChild + uint32_t(octant);
        ++level;
    }
    const Node& leaf = mNodes[index];
    return {forceOf(leaf), leaf.level, leaf.isSurface != 0};
}

Vec3d OctreeField::hitTest(const std::vector<Vec3d>& points) const
{
    Vec3d directionSum(0.0);
    double strongest = 0.0;
    std::size_t hits = 0;
    for (const Vec3d& p : points) {
        const FieldSample hit = sample(p);
        if (hit.level == 0) continue;
        ++hits;
        const double length = hit.force.length();
        if (length > 0) directionSum += Vec3d(hit.force) / length;
        strongest = std::max(strongest, length);
    }
    if (hits == 0) return Vec3d(0.0);
    const Vec3d average = directionSum / double(hits);
    if (average.length() < kZeroAverage) return Vec3d(0.0);
    return average.unitSafe() * strongest;
}

void OctreeField::collect(uint32_t index, const uint32_t cell[3], bool withInterior, std::vector<FieldLeaf>& out) const
{
    const Node& node = mNodes[index];
    const bool isLeaf = node.firstChild == 0;
    if (isLeaf || withInterior) {
        FieldLeaf leaf;
        const int shift = mDepth - node.level;
        Vec3d min, max;
        for (int axis = 0; axis < 3; ++axis) {
            leaf.origin[axis] = cell[axis] << shift;
            min[axis] = boundary(axis, cell[axis], node.level);
            max[axis] = boundary(axis, cell[axis] + 1, node.level);
        }
        leaf.width = 1u << shift;
        leaf.bounds = BBoxd(min, max);
        leaf.force = forceOf(node);
        leaf.level = node.level;
        leaf.isSurface = node.isSurface != 0;
        leaf.isLeaf = isLeaf;
        out.push_back(leaf);
    }
    if (isLeaf) return;
    for (int octant = 0; octant < 8; ++octant) {
        const uint32_t child[3] = {2 * cell[0] + (octant & 1), 2 * cell[1] + ((octant >> 1) & 1),
                                   2 * cell[2] + ((octant >> 2) & 1)};
        collect(node.firstChild + uint32_t(octant), child, withInterior, out);
    }
}

std::vector<FieldLeaf> OctreeField::leaves() const
{
    std::vector<FieldLeaf> out;
    out.reserve(mLeafCount);
    const uint32_t root[3] = {0, 0, 0};
    collect(0, root, false, out);
    return out;
}

std::vector<FieldLeaf> OctreeField::nodes() const
{
    std::vector<FieldLeaf> out;
    out.reserve(mNodes.size());
    const uint32_t root[3] = {0, 0, 0};
    collect(0, root, true, out);
    return out;
}

std::vector<FieldLeaf> OctreeField::leavesOfOctant(int octant) const
{
    std::vector<FieldLeaf> out;
    const uint32_t root[3] = {0, 0, 0};
    if (mNodes[0].firstChild == 0) {
        if (octant == 0) collect(0, root, false, out);
        return out;
    }
    const uint32_t cell[3] = {uint32_t(octant & 1), uint32_t((octant >> 1) & 1), uint32_t((octant >> 2) & 1)};
    collect(mNodes[0].firstChild + uint32_t(octant), cell, false, out);
    return out;
}

} // namespace vfield
