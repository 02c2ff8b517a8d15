#pragma once
/// @file repulsion_field.h
/// TriangleMesh (object space) -> RepulsionField: an object's repulsive field
/// as the simulator reads it, made by one of three methods, so that the
/// paper's field can be measured against what one would try instead:
///
/// - octree (the default): the paper's octree field (octree_field.h),
///   voxelized at its finest leaf (field_grid.h).
/// - distance: from the mesh's signed distance d (OpenVDB
///   meshToSignedDistanceField near the surface, extended through the root
///   cube by fast sweeping). Direction: the distance's gradient (away from
///   the surface). Magnitude: the octree's (its growth included) at level
///   1 + log2(side / max(d, voxel)), the level an octree cell as large as the
///   distance would have, so the two methods push alike at a given distance;
///   times surfaceBoost within a voxel of the surface and inside (three
///   voxels deep). Like the octree's, it fills the root cube.
/// - potentialFlow: the clouds' wind (the uniform fields acting on every cloud
///   everywhere, gravity included) flowing around the mesh instead of into it
///   (OpenVDB tools::PotentialFlow: Laplace's equation for the potential in
///   the root cube outside the mesh, no flow through its surface, the wind
///   undisturbed at the cube's faces). The field is the flow's deviation
///   from the wind, an acceleration added to the wind, not divided by mass;
///   the simulator moves particles in the band with the flow, at the terminal
///   velocity (acceleration / drag). Acts on clouds only; static objects only.
///
/// Every method gives a force grid over the field's bounds (object space:
/// the cube of side = largest extent + 2 margin around the mesh), a level
/// grid on the same voxels that says how fine the field's structure is there
/// (cellSize(level), what a particle's substep must not outrun), and the
/// paper's hit test for dynamic objects. Distance and potentialFlow default
/// to a voxel as fine as the octree's finest possible cell,
/// side / 2^(maxLevel - 1).

#include <vfield/core/math.h>
#include <vfield/core/trilinear_sampler.h>
#include <vfield/core/vdb_trees.h>
#include <vfield/field/octree_field.h>
#include <vfield/mesh/triangle_mesh.h>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace vfield {

enum class RepulsionMethod { Octree, Distance, PotentialFlow };
inline constexpr EnumName<RepulsionMethod> kRepulsionMethodNames[] = {{RepulsionMethod::Octree, "octree"},
                                                                      {RepulsionMethod::Distance, "distance"},
                                                                      {RepulsionMethod::PotentialFlow, "potentialFlow"}};
constexpr const auto& enumNames(RepulsionMethod) { return kRepulsionMethodNames; }

/// How a field is read between the centres of its voxels.
enum class FieldSampling {
    Nearest,   ///< the voxel holding the point: the paper's field, constant over each octree leaf
    Trilinear, ///< trilinear between voxel centres: smooth only within the finest cells
    /// Octree: continuous everywhere (smoothForceGrid, field_grid.h): across
    /// the faces between leaves of one level and across changes of level the
    /// force turns over a leaf's width instead of stepping at the face. Other
    /// methods, whose voxels are their structure: Trilinear.
    Dual
};
inline constexpr EnumName<FieldSampling> kFieldSamplingNames[] = {
    {FieldSampling::Nearest, "nearest"}, {FieldSampling::Trilinear, "trilinear"}, {FieldSampling::Dual, "dual"}};
constexpr const auto& enumNames(FieldSampling) { return kFieldSamplingNames; }

struct RepulsionSettings {
    RepulsionMethod method = RepulsionMethod::Octree;
    /// margin, strength, growth, surfaceBoost and flipNormals apply to every method
    /// (potentialFlow: margin only, through the root's size); maxPerLeaf, maxLevel
    /// and splitRule shape the octree, and maxLevel sets the others' default voxel.
    OctreeFieldSettings field;
    std::optional<double> voxelSize;

    /// Throws OptionError naming the first option out of range.
    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(vfield::field("method", self.method)
                  .doc("octree: the paper's field; distance: from the mesh's signed distance; potentialFlow: the "
                       "clouds' wind flowing around the mesh"));
        visit(vfield::field("voxelSize", self.voxelSize)
                  .range(1e-9, 1e12)
                  .unit("object units")
                  .defaultText("root side / 2^(maxLevel - 1)")
                  .doc("distance and potentialFlow: the grid's voxel (the octree's cells follow its triangles)"));
        visit(inlineFields(self.field));
    }
};

class RepulsionField {
public:
    /// Told, about once a second, how far a long build is ("potential flow:
    /// iteration 400 of at most 4000"), from the calling thread.
    using Progress = std::function<void(const std::string& step)>;

    /// Builds the field around the mesh. wind (object space, acceleration
    /// units) is what potentialFlow deflects; the other methods ignore it.
    /// Throws ValueError for invalid options, a mesh without triangles of
    /// non-zero area, or a potential flow whose solve does not converge.
    /// sample() reads it as `sampling` says.
    static std::shared_ptr<const RepulsionField> build(const TriangleMesh& mesh, const RepulsionSettings& options,
                                                       FieldSampling sampling = FieldSampling::Dual,
                                                       const Vec3d& wind = Vec3d(0.0), const Progress& progress = {});
    virtual ~RepulsionField() = default;

    RepulsionMethod method() const { return mMethod; }
    /// Forces (force()) are divided by the mass they push; a flow's deviation
    /// (potentialFlow) is an acceleration, the same for every mass.
    bool isFlow() const { return mMethod == RepulsionMethod::PotentialFlow; }
    const BBoxd& bounds() const { return mBounds; } ///< where it acts, object space
    double rootSide() const { return mSide; }
    int depth() const { return mDepth; } ///< the finest level present
    /// Edge of the field's structure at a level read from level(), object units.
    double cellSize(int level) const
    {
        return level >= 1 && std::size_t(level) < mCellSize.size() ? mCellSize[std::size_t(level)] : structureCellSize(level);
    }
    double finestCellSize() const { return cellSize(mDepth); }

    FieldSampling sampling() const { return mSampling; }
    /// Object space, acceleration units x mass (isFlow(): acceleration); zero
    /// outside bounds(). The octree's: the paper's field, constant over each leaf.
    const openvdb::Vec3SGrid::Ptr& force() const { return mForce; }
    /// The force as sample() reads it: force(), or with Dual sampling of an
    /// octree its smooth grid.
    const openvdb::Vec3SGrid::Ptr& sampledForce() const { return mSampled; }
    /// Levels on the force's voxels (1..depth(); 0 where the field is zero).
    const openvdb::Int32Grid::Ptr& level() const { return mLevel; }

    /// Cached reads of sampledForce() and level(), one per thread. The
    /// level is read voxel by voxel (valueAt), through the leaf (or the
    /// tile, as over a coarse octree leaf) the last read found.
    struct Accessor {
        TrilinearSampler<openvdb::Vec3STree> force;
        TrilinearSampler<openvdb::Int32Tree> level;
        /// The last levelCell(), given again for the next point in the same
        /// cell (most: particles come in spatial order).
        struct Cell {
            openvdb::Coord first; ///< its first level voxel
            int voxels = 0;       ///< its edge in level voxels; 0: none yet
            BBoxd box;
        } cell;
    };
    Accessor accessor() const { return {TrilinearSampler(mSampled->tree()), TrilinearSampler(mLevel->tree()), {}}; }
    struct Sample {
        Vec3d force;               ///< as force() holds it
        int level;                 ///< of the voxel holding the point: cellSize(level) is the structure there
        openvdb::Coord levelVoxel; ///< that voxel of level()
    };
    /// The force at an object-space point (zero outside bounds()), read as
    /// sampling() says, and the level there: what a substep needs.
    Sample sample(Accessor& accessor, const Vec3d& local) const;
    /// The level at an object-space point (0 outside bounds()): sample()'s
    /// level without the force.
    int levelAt(Accessor& accessor, const Vec3d& local) const;
    /// The box, around an object-space point inside bounds(), over which
    /// levelAt() reads the level that sample() read there: the octree leaf
    /// holding the point's level voxel (from that voxel's index: the level
    /// grid's voxels are the finest leaves, and a leaf of level l is 2^(depth
    /// - l) of them along each axis), or for the other methods that voxel;
    /// shrunk by a millionth of a voxel so that rounding cannot put a point in
    /// it on a neighbour's side (so the point itself may lie up to that far
    /// outside it). What spares a substep staying in its cell a second read
    /// of the level where it ends. Held by the accessor until its next levelCell().
    const BBoxd& levelCell(Accessor& accessor, const Sample& sample) const;

    /// The paper's hit test of another object's points (object space of this
    /// field): the normalized average of the unit directions at the points
    /// inside bounds(), with the largest magnitude among them; zero without
    /// a hit or when the directions cancel.
    virtual Vec3d hitTest(const std::vector<Vec3d>& points) const;

    /// Bytes held by the field's grids and structures.
    virtual std::size_t memoryBytes() const;

protected:
    RepulsionField() = default;

    /// Sets the sampling and the grid it reads, after mForce and mLevel exist.
    void setSampling(FieldSampling sampling, openvdb::Vec3SGrid::Ptr sampled);

    RepulsionMethod mMethod = RepulsionMethod::Octree;
    FieldSampling mSampling = FieldSampling::Nearest;
    bool mSampledOnLevelVoxels = true; ///< sampledForce() and level() share their voxels
    /// The grids' world-to-index maps, kept out of their Transforms' virtual
    /// calls (a substep reads them twice): index = (p - origin) * inverseVoxel,
    /// as OpenVDB's scale-translate map computes it.
    struct IndexMap {
        Vec3d origin, inverseVoxel;
        Vec3d operator()(const Vec3d& p) const
        {
            return Vec3d((p.x() - origin.x()) * inverseVoxel.x(), (p.y() - origin.y()) * inverseVoxel.y(),
                         (p.z() - origin.z()) * inverseVoxel.z());
        }
    };
    IndexMap mSampledIndex, mLevelIndex;
    double mLevelVoxel = 1.0; ///< level()'s voxel edge
    /// Octree: leaves are cubes of 2^(depth - level) level voxels from the
    /// root's corner (false: levelCell gives the voxel alone, as for the other methods).
    bool mLeavesOnLevelVoxels = false;
    /// cellSize(level) by level, 1..depth(), from setSampling on: every particle substep asks.
    std::vector<double> mCellSize;
    /// The method's cell size at a level (the octree's own table, or the root halved level - 1 times).
    virtual double structureCellSize(int level) const;
    BBoxd mBounds;
    double mSide = 0.0;
    int mDepth = 1;
    openvdb::Vec3SGrid::Ptr mForce, mSampled;
    openvdb::Int32Grid::Ptr mLevel;
};

} // namespace vfield
