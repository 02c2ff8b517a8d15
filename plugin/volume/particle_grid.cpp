#include <vfield/volume/particle_grid.h>

#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointCount.h>

namespace vfield {

openvdb::GridBase::Ptr makeParticleGrid(const ParticleSet& particles)
{
    using namespace openvdb;
    initialize(); // registers the point attribute types
    const points::PointAttributeVector<Vec3f> positions(particles.position);
    const float voxelSize = particles.size() > 8 ? points::computeVoxelSize(positions, 8) : 1.0f;
    const auto transform = math::Transform::createLinearTransform(voxelSize);
    const tools::PointIndexGrid::Ptr index = tools::createPointIndexGrid<tools::PointIndexGrid>(positions, *transform);
    points::PointDataGrid::Ptr grid =
        points::createPointDataGrid<points::NullCodec, points::PointDataGrid>(*index, positions, *transform);
    grid->setName("particles");

    std::vector<int32_t> ids(particles.id.begin(), particles.id.end());
    points::PointDataTree& tree = grid->tree();
    points::appendAttribute<Vec3f>(tree, "v");
    points::populateAttribute(tree, index->tree(), "v", points::PointAttributeVector<Vec3f>(particles.velocity));
    points::appendAttribute<Vec3f>(tree, "rest");
    points::populateAttribute(tree, index->tree(), "rest", points::PointAttributeVector<Vec3f>(particles.rest));
    if (!particles.rest2.empty()) {
        points::appendAttribute<Vec3f>(tree, "rest2");
        points::populateAttribute(tree, index->tree(), "rest2", points::PointAttributeVector<Vec3f>(particles.rest2));
        grid->insertMeta("rest2Weight", FloatMetadata(particles.rest2Weight));
    }
    points::appendAttribute<int32_t>(tree, "id");
    points::populateAttribute(tree, index->tree(), "id", points::PointAttributeVector<int32_t>(ids));
    points::appendAttribute<float>(tree, "pscale");
    points::populateAttribute(tree, index->tree(), "pscale", points::PointAttributeVector<float>(particles.radius));
    return grid;
}

} // namespace vfield
