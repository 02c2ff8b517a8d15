#include <vfield/volume/particle_grid.h>

#include <vfield/core/error.h>

#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointCount.h>

#include <algorithm>

namespace vfield {

namespace {

template<typename PositionCodec, typename VectorCodec, typename ScaleCodec>
openvdb::points::PointDataGrid::Ptr particleGrid(const ParticleSet& particles, bool withState)
{
    using namespace openvdb;
    const points::PointAttributeVector<Vec3f> positions(particles.position);
    // Sixteen particles a voxel: fewer voxels and leaves to store than
    // OpenVDB's usual eight, the positions still 16-bit fixed point within each.
    constexpr uint32_t kParticlesPerVoxel = 16;
    const float voxelSize =
        particles.size() > kParticlesPerVoxel ? points::computeVoxelSize(positions, kParticlesPerVoxel) : 1.0f;
    const auto transform = math::Transform::createLinearTransform(voxelSize);
    const tools::PointIndexGrid::Ptr index = tools::createPointIndexGrid<tools::PointIndexGrid>(positions, *transform);
    points::PointDataGrid::Ptr grid =
        points::createPointDataGrid<PositionCodec, points::PointDataGrid>(*index, positions, *transform);
    grid->setName("particles");

    points::PointDataTree& tree = grid->tree();
    const auto vectors = [&](const char* name, const std::vector<Vec3f>& values) {
        points::appendAttribute<Vec3f, VectorCodec>(tree, name);
        points::populateAttribute(tree, index->tree(), name, points::PointAttributeVector<Vec3f>(values));
    };
    vectors("v", particles.velocity);
    vectors("rest", particles.rest);
    if (!particles.rest2.empty()) {
        vectors("rest2", particles.rest2);
        grid->insertMeta("rest2Weight", FloatMetadata(particles.rest2Weight));
    }
    const std::vector<int32_t> ids(particles.id.begin(), particles.id.end());
    points::appendAttribute<int32_t>(tree, "id");
    points::populateAttribute(tree, index->tree(), "id", points::PointAttributeVector<int32_t>(ids));
    points::appendAttribute<float, ScaleCodec>(tree, "pscale");
    points::populateAttribute(tree, index->tree(), "pscale", points::PointAttributeVector<float>(particles.radius));
    if (!particles.fade.empty()) { // emitted particles fading in and out (CloudEmissionSettings)
        points::appendAttribute<float>(tree, "fade");
        points::populateAttribute(tree, index->tree(), "fade", points::PointAttributeVector<float>(particles.fade));
    }
    if (withState) {
        points::appendAttribute<Vec3f>(tree, "worldP");
        points::populateAttribute(tree, index->tree(), "worldP", positions);
        points::appendAttribute<float>(tree, "peak");
        points::populateAttribute(tree, index->tree(), "peak", points::PointAttributeVector<float>(particles.peak));
        points::appendAttribute<float>(tree, "origin");
        points::populateAttribute(tree, index->tree(), "origin", points::PointAttributeVector<float>(particles.origin));
        const std::vector<int32_t> clouds(particles.cloud.begin(), particles.cloud.end());
        points::appendAttribute<int32_t>(tree, "cloud");
        points::populateAttribute(tree, index->tree(), "cloud", points::PointAttributeVector<int32_t>(clouds));
    }
    return grid;
}

/// The attribute's values, point by point in the grid's order, into out.
template<typename T, typename Out>
void readAttribute(const openvdb::points::PointDataTree& tree, const std::string& name, std::vector<Out>& out)
{
    using namespace openvdb::points;
    out.clear();
    out.reserve(pointCount(tree));
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
        const AttributeHandle<T> handle(leaf->constAttributeArray(name));
        for (auto index = leaf->beginIndexOn(); index; ++index) out.push_back(Out(handle.get(*index)));
    }
}

/// The points' world positions from P, their offsets within their voxels.
void readPositions(const openvdb::points::PointDataGrid& grid, std::vector<Vec3f>& out)
{
    using namespace openvdb::points;
    out.clear();
    out.reserve(pointCount(grid.tree()));
    for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf) {
        const AttributeHandle<openvdb::Vec3f> position(leaf->constAttributeArray("P"));
        for (auto index = leaf->beginIndexOn(); index; ++index) {
            const openvdb::Vec3d voxel = index.getCoord().asVec3d() + position.get(*index);
            out.push_back(openvdb::Vec3f(grid.transform().indexToWorld(voxel)));
        }
    }
}

} // namespace

openvdb::GridBase::Ptr makeParticleGrid(const ParticleSet& particles, ParticlePrecision precision, bool withState)
{
    openvdb::initialize(); // registers the point attribute types
    using namespace openvdb::points;
    if (precision == ParticlePrecision::Full) return particleGrid<NullCodec, NullCodec, NullCodec>(particles, withState);
    // pscale in 8 bits (a 255th of a unit) when every radius fits in [0, 1]
    // as OpenVDB's unit-range codec needs; else as a 16-bit float.
    const bool unitRadii =
        std::all_of(particles.radius.begin(), particles.radius.end(), [](float r) { return r >= 0.0f && r <= 1.0f; });
    PointDataGrid::Ptr grid =
        unitRadii ? particleGrid<FixedPointCodec<false>, TruncateCodec, FixedPointCodec<true, UnitRange>>(particles, withState)
                  : particleGrid<FixedPointCodec<false>, TruncateCodec, TruncateCodec>(particles, withState);
    compactAttributes(grid->tree()); // a cloud's pscale: one value per leaf
    return grid;
}

ParticleSet readParticleGrid(const openvdb::GridBase& base)
{
    openvdb::initialize();
    using namespace openvdb::points;
    const auto* grid = dynamic_cast<const PointDataGrid*>(&base);
    if (!grid) throw ValueError("grid '" + base.getName() + "' is not a point data grid");
    const PointDataTree& tree = grid->tree();
    const auto leaf = tree.cbeginLeaf();
    const auto has = [&](const char* name) {
        return !leaf || leaf->attributeSet().descriptor().find(name) != AttributeSet::INVALID_POS;
    };
    for (const char* name : {"P", "v", "rest", "id", "pscale"})
        if (!has(name)) throw ValueError("point grid '" + base.getName() + "' has no attribute '" + name + "'");

    ParticleSet read;
    if (has("worldP")) readAttribute<openvdb::Vec3f>(tree, "worldP", read.position);
    else readPositions(*grid, read.position);
    readAttribute<openvdb::Vec3f>(tree, "v", read.velocity);
    readAttribute<openvdb::Vec3f>(tree, "rest", read.rest);
    if (has("rest2")) {
        readAttribute<openvdb::Vec3f>(tree, "rest2", read.rest2);
        if (const auto weight = grid->getMetadata<openvdb::FloatMetadata>("rest2Weight")) read.rest2Weight = weight->value();
    }
    readAttribute<int32_t>(tree, "id", read.id);
    readAttribute<float>(tree, "pscale", read.radius);
    if (has("peak")) readAttribute<float>(tree, "peak", read.peak);
    if (has("origin")) readAttribute<float>(tree, "origin", read.origin);
    if (has("fade")) readAttribute<float>(tree, "fade", read.fade);
    if (has("cloud")) readAttribute<int32_t>(tree, "cloud", read.cloud);

    read.sortById();
    return read;
}

} // namespace vfield
