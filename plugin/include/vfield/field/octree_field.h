#pragma once
/// @file octree_field.h
/// TriangleMesh (object space) -> OctreeField (object space): the repulsive
/// octree vector field of Egbert & Winkler, "Collision Free Object Movement
/// Using Vector Fields", section 3.
///
/// - Root: a cube centred on the mesh's bounding box, side = largest extent +
///   2 x margin (the user's dead space). The root is level 1.
/// - A node is split into 8 equal octants while more than maxPerLeaf triangles
///   overlap its closed box (exact triangle-box test, boxes grown by 1e-9 of
///   their size so that a triangle on a boundary reliably touches both sides)
///   and its level is below maxLevel. Beyond the paper (SplitRule::NormalCone,
///   the default), a node is also split while two of its triangles face more
///   than 90 degrees apart (a normal cone wider than a half-space): the two
///   faces of a thin part would otherwise average to nothing, or to a third
///   face's direction, and push along the part instead of away from it.
/// - Direction of every node (interior nodes included, while building): the
///   normalized average of the unit normals of the triangles overlapping it. A
///   leaf without triangles, or a node whose average is shorter than 1e-9,
///   takes its parent's direction; the root's fallback is zero.
/// - Magnitude: strength x level (MagnitudeGrowth::Linear, the paper's), or
///   strength x 2^(level - 1) (Doubling), times surfaceBoost in leaves holding
///   triangles.
/// - A point's force is that of the leaf containing it: cells are half-open
///   [min, max) per axis, closed on the root's max faces; outside the root the
///   force is zero and the level 0.
/// After building, the nodes (each with its direction) are kept, not the triangles.

#include <vfield/core/fields.h>
#include <vfield/core/math.h>
#include <vfield/mesh/triangle_mesh.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace vfield {

/// The deepest level any field may have.
constexpr int kMaxOctreeLevels = 20;

/// When a node is split.
enum class SplitRule {
    NormalCone, ///< while it holds more than maxPerLeaf triangles, or triangles whose normals oppose
    Paper,      ///< while it holds more than maxPerLeaf triangles: the paper's rule exactly
};
inline constexpr EnumName<SplitRule> kSplitRuleNames[] = {{SplitRule::NormalCone, "normalCone"}, {SplitRule::Paper, "paper"}};
constexpr const auto& enumNames(SplitRule) { return kSplitRuleNames; }

/// How a node's magnitude grows with its level.
enum class MagnitudeGrowth {
    /// strength x level: the paper's. Under a steady pull (gravity) a cloud
    /// rests where the magnitude first exceeds the pull, as far from the
    /// surface as a cell of that level is large: a thick, stepped cushion.
    Linear,
    /// strength x 2^(level - 1): twice as strong in a cell half as large, as a
    /// potential's force grows as 1 / distance; the cushion is a few cells
    /// thin and follows the ground, and no surface jump is needed to stop what
    /// comes close (a surfaceBoost of 20 flings particles off it instead).
    Doubling,
};
inline constexpr EnumName<MagnitudeGrowth> kMagnitudeGrowthNames[] = {{MagnitudeGrowth::Linear, "linear"},
                                                                      {MagnitudeGrowth::Doubling, "doubling"}};
constexpr const auto& enumNames(MagnitudeGrowth) { return kMagnitudeGrowthNames; }

/// The magnitude at a level (a fraction for the distance method's continuous
/// level), before any surface boost.
double magnitudeAtLevel(MagnitudeGrowth growth, double strength, double level);

struct OctreeFieldSettings {
    std::optional<double> margin;
    int maxPerLeaf = 6;
    int maxLevel = 8;
    double strength = 1.0;
    double surfaceBoost = 10.0;
    /// For a closed mesh meant to hold things inside it, or an open sheet
    /// wound the wrong way: the field pushes into the mesh's other side.
    bool flipNormals = false;
    SplitRule splitRule = SplitRule::NormalCone;
    MagnitudeGrowth growth = MagnitudeGrowth::Linear;

    /// Throws OptionError naming the first option out of range.
    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("margin", self.margin)
                  .range(0, 1e12)
                  .unit("object units")
                  .defaultText("10% of the largest extent")
                  .doc("dead space between the mesh's bounding box and the root cube on every side"));
        visit(
            field("maxPerLeaf", self.maxPerLeaf).range(1, 1 << 20).doc("the paper's N: a node holding more triangles is split"));
        visit(field("maxLevel", self.maxLevel).range(1, kMaxOctreeLevels).doc("deepest level; the root is level 1"));
        visit(field("strength", self.strength)
                  .range(0, 1e12)
                  .doc("magnitude at level 1, and per level when growth is linear: a force, divided by the mass it pushes"));
        visit(field("growth", self.growth)
                  .doc("how the magnitude grows with the level: linear, strength x level (the paper's), or doubling, "
                       "strength x 2^(level - 1), a thin cushion that follows the ground"));
        visit(field("surfaceBoost", self.surfaceBoost).range(1, 1e12).doc("magnitude factor in leaves holding triangles"));
        visit(field("splitRule", self.splitRule)
                  .doc("normalCone: also split a node while two of its triangles face more than 90 degrees apart (thin "
                       "parts push away on both sides); paper: the triangle count only"));
        visit(field("flipNormals", self.flipNormals)
                  .doc("build the field from reversed normals (after closed meshes are oriented outward)"));
    }
};

/// The force of the field at one point.
struct FieldSample {
    Vec3f force{0.0f, 0.0f, 0.0f}; ///< direction x magnitude; zero outside the root
    int level = 0;                 ///< level of the leaf; 0 outside the root
    bool isSurface = false;        ///< the leaf holds triangles
};

/// A leaf of the octree (or, from OctreeField::nodes(), any node), for
/// drawing and voxelizing.
struct FieldLeaf {
    BBoxd bounds;       ///< object space
    uint32_t origin[3]; ///< min corner in cells of the finest level present (depth())
    uint32_t width;     ///< edge length in those cells (a power of two)
    Vec3f force;
    int level;
    bool isSurface;
    /// False for an interior node: its own force is its triangles' average
    /// normal x the magnitude of its level, without the surface boost.
    bool isLeaf = true;
};

class OctreeField {
public:
    static constexpr int kMaxLevels = kMaxOctreeLevels;
    /// Builds the field around the mesh's triangles of non-zero area, in
    /// parallel (TBB). Throws ValueError for invalid options or a mesh without
    /// such triangles.
    static OctreeField build(const TriangleMesh& mesh, const OctreeFieldSettings& options = {});

    /// The force at p (object space). Thread-safe.
    FieldSample sample(const Vec3d& p) const;

    /// The paper's hit test of another object's triangles against this field:
    /// each point (a triangle centroid, object space of this field) that lies in
    /// the root hits one leaf. Direction: the normalized average of the hit
    /// leaves' unit directions (once per point); magnitude: the largest magnitude
    /// among them. No hit, or directions that cancel: zero.
    Vec3d hitTest(const std::vector<Vec3d>& points) const;

    const BBoxd& bounds() const { return mBounds; } ///< the root cube, object space
    double rootSide() const { return mSide; }
    int depth() const { return mDepth; } ///< deepest level present
    double cellSize(int level) const;    ///< edge length of a node at level
    double finestCellSize() const { return cellSize(mDepth); }
    std::size_t leafCount() const { return mLeafCount; }
    std::size_t memoryBytes() const { return sizeof(*this) + mNodes.capacity() * sizeof(Node); }
    const OctreeFieldSettings& settings() const { return mSettings; }

    /// The magnitude of a leaf at level, with or without surface triangles.
    double magnitude(int level, bool isSurface) const;

    /// Every leaf, depth first, octants in x-fastest order.
    std::vector<FieldLeaf> leaves() const;
    /// Every node, interior ones too (FieldLeaf::isLeaf), each before its children.
    std::vector<FieldLeaf> nodes() const;
    /// The leaves under the root's octant `octant` (0..7, x-fastest), or the
    /// root itself for octant 0 when the root is a leaf: lets callers split work.
    std::vector<FieldLeaf> leavesOfOctant(int octant) const;

    /// Internal node record (public for the builder; not part of the API).
    struct Node {
        uint32_t firstChild = 0;           ///< index of the first of 8 children; 0 for a leaf
        Vec3f direction{0.0f, 0.0f, 0.0f}; ///< unit or zero
        uint8_t level = 0;
        uint8_t isSurface = 0;
    };

private:
    OctreeField() = default;
    double boundary(int axis, uint32_t index, int level) const;
    Vec3f forceOf(const Node& node) const;
    void collect(uint32_t node, const uint32_t cell[3], bool withInterior, std::vector<FieldLeaf>& out) const;

    OctreeFieldSettings mSettings;
    Vec3d mCenter{0.0};
    double mSide = 0.0;
    double mCellSize[kMaxLevels + 2] = {};     ///< edge of a cell per level (index = level)
    double mCentralIndex[kMaxLevels + 2] = {}; ///< boundary index of the central plane per level
    BBoxd mBounds;
    int mDepth = 1;
    std::size_t mLeafCount = 0;
    std::vector<Node> mNodes; // mNodes[0] is the root; siblings are contiguous
};

} // namespace vfield
