#include <vfield/render/camera.h>
#include <vfield/render/camera_path.h>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

using namespace vfield;

namespace {

/// Poses one unit apart along +x from the origin to (20, 0, 0), then along +z
/// to (20, 0, 20), each heading the way it moves: a track with a right-angle bend.
std::vector<Transform> bendingPath()
{
    std::vector<Transform> path;
    const Quatd alongZ = Transform::rotationFromDegrees(Vec3d(0, -90, 0));
    for (int i = 0; i <= 20; ++i) path.push_back({Vec3d(i, 0, 0), Quatd::identity(), 1.0});
    for (int i = 1; i <= 20; ++i) path.push_back({Vec3d(20, 0, i), alongZ, 1.0});
    return path;
}

CameraSettings behind(const Vec3d& offset)
{
    CameraSettings settings;
    settings.follow = CameraFollowSettings{"airplane", offset};
    return settings;
}

const FirstSurfaceQuery kNothingInTheWay = [](const Vec3d&, const Vec3d&, double, double) { return std::optional<double>(); };

bool near(const Vec3d& a, const Vec3d& b) { return (a - b).length() < 1e-9; }

} // namespace

TEST_CASE("camera: a following camera rides the object's path around a bend, looking at the object", "[camera]")
{
    const std::vector<Transform> path = bendingPath();
    REQUIRE(near(path.back().rotateToWorld(Vec3d(1, 0, 0)), Vec3d(0, 0, 1)));
    const Camera camera = followCamera(behind(Vec3d(-30, 10, 0)), path, kNothingInTheWay, 64, 36);
    // 20 units back along +z, round the bend and 10 along +x: where the object
    // was, 10 up; a camera in the heading frame would stand at (20, 10, -10),
    // off the path.
    CHECK(near(camera.position(), Vec3d(10, 10, 0)));
    CHECK(near(camera.forward(), (path.back().translation - camera.position()).unitSafe()));

    // Sideways offsets are to the right of the path's heading where the camera rides.
    CHECK(near(followCamera(behind(Vec3d(-30, 10, 4)), path, kNothingInTheWay, 64, 36).position(), Vec3d(10, 10, 4)));
}

TEST_CASE("camera: a path shorter than the offset continues straight behind its first pose", "[camera]")
{
    // 50 units back: the path's 40, then 10 straight behind (0, 0, 0), along +x.
    const Camera bend = followCamera(behind(Vec3d(-50, 10, 0)), bendingPath(), kNothingInTheWay, 64, 36);
    CHECK(near(bend.position(), Vec3d(-10, 10, 0)));

    const Transform start{Vec3d(5, 0, 0), Transform::rotationFromDegrees(Vec3d(0, -90, 0)), 1.0};
    const Camera camera = followCamera(behind(Vec3d(-30, 10, 0)), {start}, kNothingInTheWay, 64, 36);
    CHECK(near(camera.position(), Vec3d(5, 10, -30)));
}

TEST_CASE("camera: an offset ahead of the object stays in its heading frame", "[camera]")
{
    const Camera camera = followCamera(behind(Vec3d(15, 5, 0)), bendingPath(), kNothingInTheWay, 64, 36);
    CHECK(near(camera.position(), Vec3d(20, 5, 35)));
}

TEST_CASE("camera: a surface between the object and the camera pulls the camera in front of it", "[camera]")
{
    const std::vector<Transform> path = bendingPath();
    const FirstSurfaceQuery wallAtHalfWay = [](const Vec3d&, const Vec3d&, double, double tMax) {
        return std::optional<double>(0.5 * tMax);
    };
    const Camera camera = followCamera(behind(Vec3d(-30, 10, 0)), path, wallAtHalfWay, 64, 36);
    const Vec3d unblocked(10, 10, 0), object = path.back().translation;
    CHECK(near(camera.position(), object + (unblocked - object) * 0.85 * 0.5));
}

TEST_CASE("camera: a box's image region holds the image of every point of the box, and little more", "[camera]")
{
    const Camera camera(Vec3d(0, 5, 40), Vec3d(3, 2, 0), Vec3d(0, 1, 0), 45.0, 320, 180);
    const BBoxd box(Vec3d(-4, 0, -6), Vec3d(10, 6, 2));
    const ImageRegion region = camera.regionOf(box);
    REQUIRE(!region.empty());
    // A grid of points over the box (its corners among them): the pixel
    // that sees each lies within the region, and the farthest on each side
    // are its edges.
    double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
    for (int i = 0; i <= 8; ++i)
        for (int j = 0; j <= 8; ++j)
            for (int k = 0; k <= 8; ++k) {
                const Vec3d p = box.min() + (box.max() - box.min()) * Vec3d(i, j, k) / 8.0;
                // The pixel that sees p, on the image plane at distance 1; direction() confirms it.
                const Vec3d d = p - camera.position();
                const double depth = d.dot(camera.forward());
                const double x = (d.dot(camera.right()) / (depth * camera.tanHalfFov() * camera.aspect()) + 1.0) * 160.0;
                const double y = (1.0 - d.dot(camera.up()) / (depth * camera.tanHalfFov())) * 90.0;
                CHECK((camera.direction(x, y) - d.unitSafe()).length() < 1e-9);
                x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x), y1 = std::max(y1, y);
            }
    CHECK(region.x0 == Approx(std::max(0.0, x0)));
    CHECK(region.y0 == Approx(std::max(0.0, y0)));
    CHECK(region.x1 == Approx(std::min(320.0, x1)));
    CHECK(region.y1 == Approx(std::min(180.0, y1)));

    // Reaching behind the camera, a box may appear anywhere: the whole image.
    const ImageRegion around = camera.regionOf(BBoxd(Vec3d(-1, 4, 30), Vec3d(1, 6, 50)));
    CHECK((around.x0 == 0.0 && around.y0 == 0.0 && around.x1 == 320.0 && around.y1 == 180.0));
}

TEST_CASE("camera: a path camera travels through its points at constant speed, looking along its path", "[camera]")
{
    CameraSettings settings;
    CameraPathSettings path;
    // Uneven legs and a sharp-ish turn: the speed must not follow the points' spacing.
    path.points = {Vec3d(0, 10, 0), Vec3d(40, 12, 0), Vec3d(50, 15, 30), Vec3d(20, 10, 60), Vec3d(25, 8, 62)};
    path.start = 10.0;
    path.end = 110.0;
    path.lookAlong = true;
    settings.path = path;
    settings.validate();

    CHECK(settings.at(0.0).position == path.points.front());
    CHECK(settings.at(10.0).position == path.points.front());
    CHECK((settings.at(110.0).position - path.points.back()).length() < 1e-9);
    CHECK(settings.at(500.0).position == settings.at(110.0).position);

    std::vector<double> steps;
    Vec3d previous = settings.at(10.0).position;
    for (int k = 1; k <= 1000; ++k) {
        const double frame = 10.0 + 0.1 * k;
        const CameraSettings camera = settings.at(frame);
        steps.push_back((camera.position - previous).length());
        // It looks the way it travels.
        const Vec3d travel = (settings.at(frame + 1e-3).position - settings.at(frame - 1e-3).position).unit();
        if (k < 1000) CHECK((camera.lookAt - camera.position).unit().dot(travel) > 0.9999);
        previous = camera.position;
    }
    const auto [slowest, fastest] = std::minmax_element(steps.begin(), steps.end());
    CHECK(*fastest / *slowest < 1.005);

    // Through every point.
    const CameraPath travelled(path.points);
    for (const Vec3d& point : path.points) {
        double nearest = 1e30;
        for (int k = 0; k <= 200000; ++k)
            nearest = std::min(nearest, (travelled.point(travelled.length() * k / 200000.0) - point).length());
        CHECK(nearest < 1e-3);
    }
}

TEST_CASE("camera: a path camera without lookAlong looks at its keyed lookAt", "[camera]")
{
    CameraSettings settings;
    settings.path = CameraPathSettings{{Vec3d(0, 10, 0), Vec3d(40, 10, 0)}, 1.0, 41.0, false};
    settings.lookAt = Vec3d(20, 0, 30);
    CHECK(settings.at(21.0).lookAt == Vec3d(20, 0, 30));
    CHECK((settings.at(21.0).position - Vec3d(20, 10, 0)).length() < 1e-6);
    settings.follow = CameraFollowSettings{"airplane", Vec3d(-30, 10, 0)};
    CHECK_THROWS_WITH(settings.validate(), Catch::Contains("a camera follows an object or travels a path, not both"));
}
