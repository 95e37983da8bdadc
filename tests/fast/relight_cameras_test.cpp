// Camera paths of the relighting tool: orbit cameras (cameras/orbit.h) look at the centre (it projects to
// the principal point) from the scene cameras' mean height and distance; camera JSON files
// (cameras/camera_json.h) round-trip exactly and bad ones fail naming the file and the entry.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <numbers>

#include "lumigauss/cameras/camera_json.h"
#include "lumigauss/cameras/orbit.h"
#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/util/error.h"
#include "support/temp_dir.h"

namespace lumigauss {
namespace {

using lumigauss::testing::TempDir;
using ::testing::HasSubstr;

Camera intrinsics() {
    Camera c;
    c.width = 64, c.height = 48;
    c.fx = 60, c.fy = 58, c.cx = 31.5, c.cy = 25.0;
    return c;
}

Vec2<double> project(const Camera& c, Vec3d world) {
    const Vec3d p = c.world_to_camera(world);
    return {c.fx * p.x / p.z + c.cx, c.fy * p.y / p.z + c.cy};
}

void expect_rotation(const Mat3d& r) {
    const Mat3d i = r * transpose(r);
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) EXPECT_NEAR(i(a, b), a == b ? 1.0 : 0.0, 1e-12);
    EXPECT_NEAR(dot(cross(r.row(0), r.row(1)), r.row(2)), 1.0, 1e-12);
}

std::string message_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

// ---- look_at and orbits ---------------------------------------------------------------------------------

TEST(RelightCameras, LookAtPutsTheTargetAtThePrincipalPointWithUpUp) {
    const Vec3d target{1, -2, 0.5};
    for (const char* name : {"+z", "-y", "+x"}) {
        const Vec3d up = parse_up_axis(name);
        Vec3d e1, e2;
        orbit_basis(up, e1, e2);
        const Vec3d eye = target + 3.0 * e1 + 1.0 * e2 + 2.0 * up;
        const Camera c = look_at(intrinsics(), eye, target, up);
        expect_rotation(c.rotation);
        const Vec2<double> uv = project(c, target);
        EXPECT_NEAR(uv.x, c.cx, 1e-9) << name;
        EXPECT_NEAR(uv.y, c.cy, 1e-9) << name;
        EXPECT_NEAR(length(c.center() - eye), 0.0, 1e-12);
        // A point above the target is higher in the image (smaller row), not left or right of it.
        const Vec2<double> above = project(c, target + 0.1 * up);
        EXPECT_LT(above.y, c.cy) << name;
        EXPECT_NEAR(above.x, c.cx, 1e-9) << name;
    }
    // Straight down along up: still a valid camera.
    const Camera down = look_at(intrinsics(), target + 5.0 * Vec3d{0, 0, 1}, target, Vec3d{0, 0, 1});
    expect_rotation(down.rotation);
    EXPECT_NEAR(project(down, target).x, down.cx, 1e-9);
    EXPECT_THROW(look_at(intrinsics(), target, target, Vec3d{0, 0, 1}), Error);
}

TEST(RelightCameras, OrbitCirclesTheCentreAtTheCamerasHeightAndDistance) {
    const Vec3d centre{1, 2, 3};
    for (const char* name : {"+z", "-y"}) {
        const Vec3d up = parse_up_axis(name);
        Vec3d e1, e2;
        orbit_basis(up, e1, e2);
        // Scene cameras at heights 1..3 (mean 2) and distances 4..6 (mean 5) around the centre.
        std::vector<Camera> scene;
        for (int i = 0; i < 3; ++i) {
            const double a = 0.4 + 1.1 * i, h = 1.0 + i, r = 4.0 + i;
            const Vec3d eye = centre + h * up + r * (std::cos(a) * e1 + std::sin(a) * e2);
            scene.push_back(look_at(intrinsics(), eye, centre + Vec3d{0.1, 0.2, 0.0}, up));
        }
        const Orbit orbit = orbit_from_cameras(scene, centre, up);
        EXPECT_NEAR(orbit.height, 2.0, 1e-12);
        EXPECT_NEAR(orbit.radius, 5.0, 1e-12);
        EXPECT_NEAR(orbit.start_azimuth, 0.4, 1e-12);
        const std::vector<NamedCamera> cams = orbit_cameras(orbit, intrinsics(), 12);
        ASSERT_EQ(cams.size(), 12u);
        EXPECT_EQ(cams[0].name, "orbit_000");
        EXPECT_EQ(cams[11].name, "orbit_011");
        for (std::size_t k = 0; k < cams.size(); ++k) {
            const Camera& c = cams[k].camera;
            EXPECT_EQ(c.width, 64);
            EXPECT_DOUBLE_EQ(c.fx, 60.0);
            expect_rotation(c.rotation);
            const Vec2<double> uv = project(c, centre);
            EXPECT_NEAR(uv.x, c.cx, 1e-9) << name << " " << k;
            EXPECT_NEAR(uv.y, c.cy, 1e-9) << name << " " << k;
            EXPECT_GT(c.world_to_camera(centre).z, 0.0);
            const Vec3d off = c.center() - centre;
            EXPECT_NEAR(dot(off, up), 2.0, 1e-9);
            EXPECT_NEAR(length(off - dot(off, up) * up), 5.0, 1e-9);
            const double a = std::atan2(dot(off, e2), dot(off, e1));
            const double expected = 0.4 + 2 * std::numbers::pi * double(k) / 12.0;
            EXPECT_NEAR(std::remainder(a - expected, 2 * std::numbers::pi), 0.0, 1e-9) << k;
        }
    }
}

TEST(RelightCameras, OrbitNeedsCamerasOffTheAxis) {
    EXPECT_THROW(orbit_from_cameras({}, Vec3d{}, Vec3d{0, 0, 1}), Error);
    const Camera above = look_at(intrinsics(), Vec3d{0, 0, 5}, Vec3d{}, Vec3d{0, 0, 1});
    EXPECT_THROW(orbit_from_cameras({above}, Vec3d{}, Vec3d{0, 0, 1}), Error);
    Orbit o;
    EXPECT_THROW(orbit_cameras(o, intrinsics(), 0), Error);
}

TEST(RelightCameras, PointCloudCentreIsThePerAxisMedian) {
    std::vector<Vec3f> pts = {{0, 0, 0}, {1, 10, -1}, {2, 20, -2}, {1000, -500, 7}, {3, 30, -3}};
    const Vec3d c = point_cloud_centre(pts);
    EXPECT_DOUBLE_EQ(c.x, 2.0);
    EXPECT_DOUBLE_EQ(c.y, 10.0);
    EXPECT_DOUBLE_EQ(c.z, -1.0);
    EXPECT_THROW(point_cloud_centre({}), Error);
}

TEST(RelightCameras, FrameNames) {
    EXPECT_EQ(frame_name("orbit_", 7, 60), "orbit_007");
    EXPECT_EQ(frame_name("x_spin", 12, 1000), "x_spin012");
    EXPECT_EQ(frame_name("x_spin", 12, 1001), "x_spin0012");
}

// ---- Camera JSON ----------------------------------------------------------------------------------------

TEST(RelightCameras, CameraJsonRoundTripsExactly) {
    TempDir tmp("relight_camera_json");
    const Orbit o{Vec3d{0.1, -0.3, 0.7}, Vec3d{0, 0, 1}, 1.234567890123, 4.5, 0.3};
    std::vector<NamedCamera> cams = orbit_cameras(o, intrinsics(), 5);
    cams[2].name = "sub/frame two";
    cams[3].camera.cx = 1.0 / 3.0;
    write_camera_json(tmp / "cams.json", cams);
    const std::vector<NamedCamera> back = read_camera_json(tmp / "cams.json");
    ASSERT_EQ(back.size(), cams.size());
    for (std::size_t i = 0; i < cams.size(); ++i) {
        EXPECT_EQ(back[i].name, cams[i].name);
        const Camera &a = cams[i].camera, &b = back[i].camera;
        EXPECT_EQ(a.width, b.width);
        EXPECT_EQ(a.height, b.height);
        EXPECT_EQ(a.fx, b.fx);
        EXPECT_EQ(a.fy, b.fy);
        EXPECT_EQ(a.cx, b.cx);
        EXPECT_EQ(a.cy, b.cy);
        for (int r = 0; r < 3; ++r) {
            EXPECT_EQ(a.translation[r], b.translation[r]);
            for (int c = 0; c < 3; ++c) EXPECT_EQ(a.rotation(r, c), b.rotation(r, c));
        }
    }
}

TEST(RelightCameras, CameraJsonAcceptsFlatRotationsObjectsAndDefaultNames) {
    TempDir tmp("relight_camera_json_forms");
    {
        std::ofstream f(tmp / "cams.json");
        f << R"({"cameras": [
              {"width": 8, "height": 6, "fx": 5, "fy": 5, "cx": 4, "cy": 3,
               "R": [1, 0, 0, 0, 1, 0, 0, 0, 1], "t": [0, 0, 2]},
              {"name": "b", "width": 8, "height": 6, "fx": 5, "fy": 5, "cx": 4, "cy": 3,
               "R": [[0, -1, 0], [1, 0, 0], [0, 0, 1]], "t": [0.5, 0, 2]}]})";
    }
    const std::vector<NamedCamera> cams = read_camera_json(tmp / "cams.json");
    ASSERT_EQ(cams.size(), 2u);
    EXPECT_EQ(cams[0].name, "cam_000");
    EXPECT_EQ(cams[1].name, "b");
    EXPECT_EQ(cams[1].camera.rotation(0, 1), -1.0);
    EXPECT_EQ(cams[1].camera.translation.x, 0.5);
}

TEST(RelightCameras, BadCameraJsonNamesTheFileAndTheEntry) {
    TempDir tmp("relight_camera_json_bad");
    const std::string good =
        R"({"name": "ok", "width": 8, "height": 6, "fx": 5, "fy": 5, "cx": 4, "cy": 3,
            "R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 0, 2]})";
    struct Case {
        std::string text, expect;
    };
    const std::vector<Case> cases = {
        {"[" + good + ", ", "not valid JSON"},
        {"{\"a\": 1}", "list of cameras"},
        {"[]", "empty"},
        {"[" + good + ", 3]", "cameras[1]: expected an object"},
        {"[" + good + R"(, {"name": "x", "width": 8, "height": 6, "fy": 5, "cx": 4, "cy": 3,
            "R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 0, 2]}])",
         "cameras[1]: needs a number \"fx\""},
        {R"([{"width": 0, "height": 6, "fx": 5, "fy": 5, "cx": 4, "cy": 3,
            "R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 0, 2]}])",
         "cameras[0]: needs a positive integer \"width\""},
        {R"([{"width": 8, "height": 6, "fx": 5, "fy": 5, "cx": 4, "cy": 3,
            "R": [[2, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 0, 2]}])",
         "cameras[0]: \"R\" is not orthonormal"},
        {R"([{"width": 8, "height": 6, "fx": 5, "fy": 5, "cx": 4, "cy": 3,
            "R": [[-1, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 0, 2]}])",
         "cameras[0]: \"R\" is a reflection"},
        {R"([{"width": 8, "height": 6, "fx": 5, "fy": 5, "cx": 4, "cy": 3,
            "R": [[1, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 0, 2]}])",
         "cameras[0]: \"R\" must be a 3x3 rotation"},
        {R"([{"width": 8, "height": 6, "fx": 5, "fy": 5, "cx": 4, "cy": 3,
            "R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 2]}])",
         "cameras[0]: needs \"t\""},
        {"[" + good + ", " + good + "]", "cameras[1]: name 'ok' is used twice"},
        // A render allocates its buffers for the camera: 10^6 x 10^6 was accepted.
        {R"([{"width": 1000000, "height": 1000000, "fx": 5, "fy": 5, "cx": 4, "cy": 3,
            "R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 0, 2]}])",
         "cameras[0]: 1000000 x 1000000 pixels is over the limit"},
        {R"([{"name": "../x", "width": 8, "height": 6, "fx": 5, "fy": 5, "cx": 4, "cy": 3,
            "R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 0, 2]}])",
         "cameras[0]: name '../x'"},
    };
    for (std::size_t i = 0; i < cases.size(); ++i) {
        const std::string path = tmp / ("bad" + std::to_string(i) + ".json");
        {
            std::ofstream f(path);
            f << cases[i].text;
        }
        const std::string msg = message_of([&] { read_camera_json(path); });
        EXPECT_THAT(msg, HasSubstr(path)) << i;
        EXPECT_THAT(msg, HasSubstr(cases[i].expect)) << i;
    }
    EXPECT_THAT(message_of([&] { read_camera_json(tmp / "missing.json"); }), HasSubstr("missing.json"));
}

}  // namespace
}  // namespace lumigauss
