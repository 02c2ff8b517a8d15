#include <vfield/core/error.h>
#include <vfield/field/field_slice.h>
#include <vfield/mesh/procedural.h>

#include <catch2/catch.hpp>

using namespace vfield;

namespace {

bool isMeshRed(const OIIO::ImageBuf& image, int x, int y)
{
    float rgb[3];
    image.getpixel(x, y, rgb, 3);
    return rgb[0] > 0.9f && rgb[1] < 0.2f && rgb[2] < 0.2f;
}

} // namespace

TEST_CASE("field slice: the mesh's cut is drawn where the plane crosses it", "[field][image]")
{
    // The box [-1,1]^3 with margin 1: root [-2,2]^3; slice z = 0 seen from +z.
    OctreeFieldSettings options;
    options.margin = 1.0;
    const TriangleMesh box = makeBox({});
    const OctreeField field = OctreeField::build(box, options);
    FieldSliceOptions slice;
    slice.size = 400; // 100 pixels per unit, border 16
    const OIIO::ImageBuf image = drawFieldSlice(field, box, slice);
    REQUIRE(image.spec().width == 432);
    REQUIRE(image.spec().nchannels == 3);
    // The square's sides x = -1 and x = +1 at y = 0: pixels 116 and 316, row 216.
    CHECK(isMeshRed(image, 116, 216));
    CHECK(isMeshRed(image, 316, 216));
    // Its inside and the dead space are not red.
    CHECK_FALSE(isMeshRed(image, 216, 216));
    CHECK_FALSE(isMeshRed(image, 50, 216));
}

TEST_CASE("field slice: a plane that misses the field is refused", "[field][image]")
{
    const TriangleMesh box = makeBox({});
    const OctreeField field = OctreeField::build(box);
    FieldSliceOptions slice;
    slice.at = 5.0;
    CHECK_THROWS_AS(drawFieldSlice(field, box, slice), ValueError);
}
