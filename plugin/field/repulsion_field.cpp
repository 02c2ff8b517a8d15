#include <vfield/field/repulsion_field.h>

#include <vfield/core/error.h>
#include <vfield/core/field_visitors.h>
#include <vfield/core/stopwatch.h>
#include <vfield/field/field_grid.h>

#include <openvdb/tools/FastSweeping.h>
#include <openvdb/tools/GridOperators.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/PotentialFlow.h>
#include <openvdb/tree/LeafManager.h>

#include <algorithm>
#include <cmath>

namespace vfield {

void RepulsionSettings::validate() const
{
    checkFields(*this);
    if (voxelSize)
        require(method != RepulsionMethod::Octree, "voxelSize",
                "applies to the distance and potentialFlow methods (the octree's cells follow its triangles)");
}

double RepulsionField::structureCellSize(int level) const { return mSide * std::ldexp(1.0, 1 - level); }

namespace {

/// The world-to-index map of a grid made by createLinearTransform and
/// postTranslate (every field grid is), as OpenVDB's map computes it.
template<typename IndexMap>
IndexMap indexMapOf(const openvdb::math::Transform& transform)
{
    using namespace openvdb::math;
    if (const auto map = transform.constMap<UniformScaleTranslateMap>()) return {map->getTranslation(), map->getInvScale()};
    if (const auto map = transform.constMap<ScaleTranslateMap>()) return {map->getTranslation(), map->getInvScale()};
    if (const auto map = transform.constMap<UniformScaleMap>()) return {Vec3d(0.0), map->getInvScale()};
    if (const auto map = transform.constMap<ScaleMap>()) return {Vec3d(0.0), map->getInvScale()};
    throw std::logic_error("a repulsion field's grid has a " + transform.mapType() + " map, not a scale and translation");
}

} // namespace

void RepulsionField::setSampling(FieldSampling sampling, openvdb::Vec3SGrid::Ptr sampled)
{
    mSampling = sampling;
    mSampled = sampled ? std::move(sampled) : mForce;
    mSampledOnLevelVoxels = mSampled->transform() == mLevel->transform();
    mSampledIndex = indexMapOf<IndexMap>(mSampled->transform());
    mLevelIndex = indexMapOf<IndexMap>(mLevel->transform());
    mLevelVoxel = 1.0 / mLevelIndex.inverseVoxel.x();
    // voxelizeField's default: the finest leaves' lattice, voxel 0 at the root's corner.
    mLeavesOnLevelVoxels = mMethod == RepulsionMethod::Octree && mLevelIndex.origin == mBounds.min() + Vec3d(0.5 * mLevelVoxel);
    mCellSize.assign(std::size_t(mDepth) + 1, 0.0);
    for (int level = 1; level <= mDepth; ++level) {
        mCellSize[std::size_t(level)] = structureCellSize(level);
        mLeavesOnLevelVoxels = mLeavesOnLevelVoxels && mCellSize[std::size_t(level)] == std::ldexp(mLevelVoxel, mDepth - level);
    }
}

RepulsionField::Sample RepulsionField::sample(Accessor& accessor, const Vec3d& local) const
{
    const Vec3d index = mSampledIndex(local);
    const openvdb::Coord levelVoxel = openvdb::Coord::round(mSampledOnLevelVoxels ? index : mLevelIndex(local));
    const int level = accessor.level.valueAt(levelVoxel);
    if (mSampling == FieldSampling::Nearest) {
        const openvdb::Coord forceVoxel = mSampledOnLevelVoxels ? levelVoxel : openvdb::Coord::round(index);
        return {Vec3d(accessor.force.valueAt(forceVoxel)), level, levelVoxel};
    }
    return {Vec3d(accessor.force.atIndex(index)), level, levelVoxel};
}

int RepulsionField::levelAt(Accessor& accessor, const Vec3d& local) const
{
    return accessor.level.valueAt(openvdb::Coord::round(mLevelIndex(local)));
}

const BBoxd& RepulsionField::levelCell(Accessor& accessor, const Sample& sample) const
{
    // The cell's edge in level voxels, and its first voxel.
    const int voxels = mLeavesOnLevelVoxels && sample.level >= 1 && sample.level <= mDepth ? 1 << (mDepth - sample.level) : 1;
    const openvdb::Coord first = sample.levelVoxel & ~(voxels - 1);
    Accessor::Cell& cell = accessor.cell;
    if (voxels != cell.voxels || first != cell.first) {
        // Voxel i spans index i - 0.5 to i + 0.5.
        const Vec3d corner = mLevelIndex.origin + (first.asVec3d() - Vec3d(0.5)) * mLevelVoxel;
        const double margin = 1e-6 * mLevelVoxel;
        cell = {first, voxels, BBoxd(corner + Vec3d(margin), corner + Vec3d(voxels * mLevelVoxel - margin))};
    }
    return cell.box;
}

Vec3d RepulsionField::hitTest(const std::vector<Vec3d>& points) const
{
    openvdb::Vec3SGrid::ConstAccessor accessor = mForce->getConstAccessor();
    Vec3d directions(0.0);
    double strongest = 0.0;
    for (const Vec3d& p : points) {
        if (!mBounds.isInside(p)) continue;
        openvdb::Vec3s f;
        openvdb::tools::BoxSampler::sample(accessor, mForce->transform().worldToIndex(p), f);
        const double magnitude = f.length();
        if (!(magnitude > 0.0)) continue;
        directions += Vec3d(f) / magnitude;
        strongest = std::max(strongest, magnitude);
    }
    const double length = directions.length();
    return length < 1e-9 ? Vec3d(0.0) : directions * (strongest / length);
}

std::size_t RepulsionField::memoryBytes() const
{
    return std::size_t(mForce->memUsage() + mLevel->memUsage() + (mSampled != mForce ? mSampled->memUsage() : 0));
}

namespace {

class OctreeRepulsion final : public RepulsionField {
public:
    OctreeRepulsion(const TriangleMesh& mesh, const OctreeFieldSettings& options, FieldSampling sampling)
        : mOctree(OctreeField::build(mesh, options))
    {
        mMethod = RepulsionMethod::Octree;
        mBounds = mOctree.bounds();
        mSide = mOctree.rootSide();
        mDepth = mOctree.depth();
        VoxelizeOptions voxelize;
        voxelize.withSurface = false;
        const FieldGrids grids = voxelizeField(mOctree, voxelize);
        mForce = grids.force;
        mLevel = grids.level;
        setSampling(sampling, sampling == FieldSampling::Dual ? smoothForceGrid(mOctree) : nullptr);
    }
    double structureCellSize(int level) const override { return mOctree.cellSize(level); }
    Vec3d hitTest(const std::vector<Vec3d>& points) const override { return mOctree.hitTest(points); }
    std::size_t memoryBytes() const override { return mOctree.memoryBytes() + RepulsionField::memoryBytes(); }

private:
    OctreeField mOctree;
};

/// The grid-based methods: distance and potentialFlow share the root cube,
/// the voxel and the level a distance maps to.
class GridRepulsion final : public RepulsionField {
public:
    GridRepulsion(const TriangleMesh& mesh, const RepulsionSettings& options, FieldSampling sampling, const Vec3d& wind,
                  const Progress& progress);

private:
    /// The level of an octree cell about as large as the distance d (at most d, at least a voxel).
    int levelAt(double d) const
    {
        const double levels = std::ceil(std::log2(mSide / std::max(d, mVoxel)) - 1e-9);
        return std::clamp(1 + int(levels), 1, mDepth);
    }
    /// Every voxel of the root cube, active.
    openvdb::MaskGrid::Ptr rootMask() const;
    openvdb::FloatGrid::Ptr signedDistance(const TriangleMesh& mesh, double exteriorVoxels, double interiorVoxels) const;
    void buildDistance(const TriangleMesh& mesh);
    void buildPotentialFlow(const TriangleMesh& mesh, const Vec3d& wind, const Progress& progress);

    RepulsionSettings mOptions;
    double mMargin = 0.0, mVoxel = 0.0;
    openvdb::math::Transform::Ptr mTransform;
};

GridRepulsion::GridRepulsion(const TriangleMesh& mesh, const RepulsionSettings& options, FieldSampling sampling,
                             const Vec3d& wind, const Progress& progress)
    : mOptions(options)
{
    mMethod = options.method;
    BBoxd box;
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
        if (mesh.areaVector(i).lengthSqr() > 0.0)
            for (int corner = 0; corner < 3; ++corner) box.expand(Vec3d(mesh.points[mesh.triangles[i][corner]]));
    if (box.empty()) throw ValueError("the mesh has no triangle of non-zero area to build a field around");
    const double extent = box.extents()[box.maxExtent()];
    mMargin = options.field.margin.value_or(0.1 * extent);
    mSide = extent + 2.0 * mMargin;
    if (!(mSide > 0.0)) throw ValueError("the mesh and margin have no extent to build a field in");
    mBounds = BBoxd(box.getCenter() - Vec3d(0.5 * mSide), box.getCenter() + Vec3d(0.5 * mSide));
    mVoxel = options.voxelSize.value_or(mSide * std::ldexp(1.0, 1 - options.field.maxLevel));
    if (mSide / mVoxel > double(1 << 16))
        throw ValueError("voxel size " + std::to_string(mVoxel) + " gives " + std::to_string(mSide / mVoxel) +
                         " voxels across the field (at most 65536)");
    mDepth = 1 + int(std::ceil(std::log2(mSide / mVoxel) - 1e-9));
    mTransform = openvdb::math::Transform::createLinearTransform(mVoxel);
    if (mMethod == RepulsionMethod::Distance) buildDistance(mesh);
    else buildPotentialFlow(mesh, wind, progress);
    mForce->setName("force");
    mForce->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    mLevel->setName("level");
    // The voxels are the structure: dual sampling is trilinear.
    setSampling(sampling == FieldSampling::Dual ? FieldSampling::Trilinear : sampling, nullptr);
}

openvdb::MaskGrid::Ptr GridRepulsion::rootMask() const
{
    openvdb::MaskGrid::Ptr root = openvdb::MaskGrid::create(false);
    root->setTransform(mTransform->copy());
    root->tree().fill(openvdb::CoordBBox(openvdb::Coord::floor(mTransform->worldToIndex(mBounds.min())),
                                         openvdb::Coord::ceil(mTransform->worldToIndex(mBounds.max()))),
                      true, true);
    return root;
}

openvdb::FloatGrid::Ptr GridRepulsion::signedDistance(const TriangleMesh& mesh, double exteriorVoxels,
                                                      double interiorVoxels) const
{
    const std::vector<openvdb::Vec3I> triangles(mesh.triangles.begin(), mesh.triangles.end());
    openvdb::FloatGrid::Ptr sdf = openvdb::tools::meshToSignedDistanceField<openvdb::FloatGrid>(
        *mTransform, mesh.points, triangles, {}, float(exteriorVoxels), float(interiorVoxels));
    sdf->setGridClass(openvdb::GRID_LEVEL_SET);
    return sdf;
}

void GridRepulsion::buildDistance(const TriangleMesh& mesh)
{
    // Exact near the surface, extended through the whole root by fast
    // sweeping, so that the field fills its root as the octree's does.
    const openvdb::FloatGrid::Ptr sdf = openvdb::tools::maskSdf(*signedDistance(mesh, 3.0, 3.0), *rootMask());
    const openvdb::Vec3SGrid::Ptr gradient = openvdb::tools::gradient(*sdf);
    const double sign = mOptions.field.flipNormals ? -1.0 : 1.0;
    const double strength = mOptions.field.strength, boost = mOptions.field.surfaceBoost;

    mForce = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    mForce->setTree(std::make_shared<openvdb::Vec3STree>(sdf->tree(), openvdb::Vec3s(0.0f), openvdb::TopologyCopy()));
    mLevel = openvdb::Int32Grid::create(0);
    mLevel->setTree(std::make_shared<openvdb::Int32Tree>(sdf->tree(), 0, openvdb::TopologyCopy()));
    mForce->tree().voxelizeActiveTiles(); // every voxel its own value; a leaf each for the pass below
    mLevel->tree().voxelizeActiveTiles();
    mForce->setTransform(mTransform->copy());
    mLevel->setTransform(mTransform->copy());

    // Each voxel from its own distance and gradient: independent of the thread count.
    openvdb::tree::LeafManager<openvdb::Vec3STree> leaves(mForce->tree());
    leaves.foreach ([&](openvdb::Vec3STree::LeafNodeType& leaf, std::size_t) {
        openvdb::FloatGrid::ConstAccessor distances = sdf->getConstAccessor();
        openvdb::Vec3SGrid::ConstAccessor gradients = gradient->getConstAccessor();
        // The same topology: the level leaf exists, and only this task writes it.
        openvdb::Int32Tree::LeafNodeType& levels = *mLevel->tree().probeLeaf(leaf.origin());
        for (auto it = leaf.beginValueOn(); it; ++it) {
            const openvdb::Coord ijk = it.getCoord();
            const double d = sign * distances.getValue(ijk);
            Vec3d direction = sign * Vec3d(gradients.getValue(ijk));
            if (!mBounds.isInside(mTransform->indexToWorld(ijk)) || !(direction.lengthSqr() > 1e-12)) {
                it.setValue(openvdb::Vec3s(0.0f));
                it.setValueOff();
                levels.setValueOff(it.pos(), 0);
                continue;
            }
            direction.normalize();
            const double level = 1.0 + std::log2(mSide / std::max(d, mVoxel));
            const double magnitude = magnitudeAtLevel(mOptions.field.growth, strength, level) * (d < mVoxel ? boost : 1.0);
            it.setValue(openvdb::Vec3s(direction * magnitude));
            levels.setValueOnly(it.pos(), levelAt(d));
        }
    });
    openvdb::tools::pruneInactive(mForce->tree());
    openvdb::tools::pruneInactive(mLevel->tree());
}

/// OpenVDB's interrupter interface for its solvers, never interrupting: the
/// conjugate gradient asks once per iteration, which is told about once a second.
class IterationCounter final : public openvdb::util::NullInterrupter {
public:
    IterationCounter(const RepulsionField::Progress& progress, int maxIterations) : mProgress(progress), mMax(maxIterations) {}
    bool wasInterrupted(int = -1) override
    {
        ++mIterations;
        if (mProgress && mSinceTold.lapAfter(1.0)) {
            mProgress("potential flow: iteration " + std::to_string(mIterations) + " of at most " + std::to_string(mMax));
        }
        return false;
    }

private:
    const RepulsionField::Progress& mProgress;
    int mMax, mIterations = 0;
    Stopwatch mSinceTold;
};

void GridRepulsion::buildPotentialFlow(const TriangleMesh& mesh, const Vec3d& wind, const Progress& progress)
{
    // A thin level set: OpenVDB takes its exterior band as the solid's
    // boundary, where the flow must not pass through.
    const openvdb::FloatGrid::Ptr collider = signedDistance(mesh, 3.0, 3.0);
    // The whole root outside the mesh, as the octree's field fills it: the wind
    // held undisturbed only at the root's faces turns smoothly, where a band as
    // thin as the margin turned it at the band's edge at once.
    const openvdb::MaskGrid::Ptr domain = rootMask();
    domain->tree().topologyDifference(openvdb::tools::interiorMask(*collider)->tree());
    mLevel = openvdb::Int32Grid::create(0);
    mLevel->setTree(std::make_shared<openvdb::Int32Tree>(domain->tree(), 0, openvdb::TopologyCopy()));
    mLevel->tree().voxelizeActiveTiles();
    for (auto it = mLevel->tree().beginValueOn(); it; ++it) it.setValue(mDepth);
    mLevel->setTransform(mTransform->copy());
    mForce = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    mForce->setTransform(mTransform->copy());
    if (!(wind.lengthSqr() > 0.0)) return; // nothing flows: nothing to deflect

    const openvdb::Vec3SGrid::Ptr neumann = openvdb::tools::createPotentialFlowNeumannVelocities(
        *collider, *domain, openvdb::Vec3SGrid::ConstPtr(), openvdb::Vec3s(wind));
    openvdb::math::pcg::State state = openvdb::math::pcg::terminationDefaults<float>();
    state.iterations = 4000;
    state.relativeError = 1e-6;
    state.absoluteError = 1e-6 * wind.length() * mVoxel;
    IterationCounter counter(progress, state.iterations);
    openvdb::util::NullInterrupter* interrupter = &counter; // the solver takes its interrupter by the base's pointer
    const openvdb::FloatGrid::Ptr potential = openvdb::tools::computeScalarPotential(*domain, *neumann, state, interrupter);
    if (!state.success)
        throw ValueError("the potential flow around the mesh did not converge (" + std::to_string(state.iterations) +
                         " iterations, error " + std::to_string(state.absoluteError) + ")");
    // The potential's gradient is the flow a solid moving with the wind would
    // push; in the solid's frame the wind's deviation is its opposite, which
    // cancels the wind's component into the surface there.
    mForce = openvdb::tools::computePotentialFlow(*potential, *neumann);
    for (auto it = mForce->tree().beginValueOn(); it; ++it) it.setValue(-*it);
    mForce->setTransform(mTransform->copy());
}

} // namespace

std::shared_ptr<const RepulsionField> RepulsionField::build(const TriangleMesh& mesh, const RepulsionSettings& options,
                                                            FieldSampling sampling, const Vec3d& wind, const Progress& progress)
{
    options.validate();
    openvdb::initialize(); // OpenVDB's solvers log through it
    if (options.method == RepulsionMethod::Octree) return std::make_shared<OctreeRepulsion>(mesh, options.field, sampling);
    return std::make_shared<GridRepulsion>(mesh, options, sampling, wind, progress);
}

} // namespace vfield
