#include <vfield/volume/particle_grid.h>

#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointCount.h>

#include <algorithm>

namespace vfield {

namespace {

template<typename PositionCodec, typename VectorCodec, typename ScaleCodec>
openvdb::points::PointDataGrid::Ptr particleGrid(const ParticleSet& particles)
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
    return grid;
}

} // namespace

openvdb::GridBase::Ptr makeParticleGrid(const ParticleSet& particles, ParticlePrecision precision)
{
    openvdb::initialize(); // registers the point attribute types
    using namespace openvdb::points;
    if (precision == ParticlePrecision::Full) return particleGrid<NullCodec, NullCodec, NullCodec>(particles);
    // pscale in 8 bits (a 255th of a unit) when every radius fits in [0, 1]
    // as OpenVDB's unit-range codec needs; else as a 16-bit float.
    const bool unitRadii =
        std::all_of(particles.radius.begin(), particles.radius.end(), [](float r) { return r >= 0.0f && r <= 1.0f; });
    PointDataGrid::Ptr grid =
        unitRadii ? particleGrid<FixedPointCodec<false>, TruncateCodec, FixedPointCodec<true, UnitRange>>(particles)
                  : particleGrid<FixedPointCodec<false>, TruncateCodec, TruncateCodec>(particles);
    compactAttributes(grid->tree()); // a cloud's pscale: one value per leaf
    return grid;
}

} // namespace vfield
