// export/world_turn.h: the rotation between two directions, a turned model's geometry, and `--orient`.
#include <gtest/gtest.h>

#include "export_test_scene.h"
#include "lumigauss/export/world_turn.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

void expect_rotation(const Mat3d& R) {
    const Mat3d I = R * transpose(R);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) EXPECT_NEAR(I(i, j), i == j ? 1.0 : 0.0, 1e-12);
    EXPECT_NEAR(dot(cross(R * Vec3d{1, 0, 0}, R * Vec3d{0, 1, 0}), R * Vec3d{0, 0, 1}), 1.0, 1e-12);
}

TEST(ExportWorldTurn, RotationTakingMapsOneDirectionOntoTheOther) {
    const Vec3d dirs[] = {{0, 0, 1},  {0, -1, 0},       {0, 1, 0},      {1, 0, 0},
                          {-1, 0, 0}, {0.2, -0.3, 0.9}, {-0.5, 0.1, -2}};
    for (const Vec3d& from : dirs)
        for (const Vec3d& to : dirs) {
            const Mat3d R = rotation_taking(from, to);
            expect_rotation(R);
            const Vec3d got = R * normalize(from), want = normalize(to);
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], 1e-12);
        }
    // The smallest rotation: a vector perpendicular to both stays.
    const Vec3d axis = rotation_taking({0, 0, 1}, {0, 1, 0}) * Vec3d{1, 0, 0};
    EXPECT_NEAR(axis.x, 1, 1e-12);
}

TEST(ExportWorldTurn, TurnedModelAndCamerasAndOrientations) {
    const GaussianModel model = export_test::cube_model(3, 10);
    const Vec3d up{0.2, -0.3, 0.9};
    const Mat3d R = orientation_rotation(ExportOrientation::YDown, up);
    const Vec3d down = R * normalize(up);
    EXPECT_NEAR(down.y, -1, 1e-12);
    const std::vector<Vec3d> cameras = {{1, 2, 3}};
    const TurnedWorld world = turn_world(model, cameras, R);
    ASSERT_EQ(world.model.size(), model.size());
    const Vec3d c = R * cameras[0];
    EXPECT_NEAR(world.cameras[0].x, c.x, 1e-12);
    for (std::size_t i = 0; i < model.size(); ++i) {
        const auto& a = model.param(ModelParam::Xyz);
        const Vec3d p = R * Vec3d{a[3 * i], a[3 * i + 1], a[3 * i + 2]};
        for (int k = 0; k < 3; ++k)
            EXPECT_NEAR(world.model.param(ModelParam::Xyz)[3 * i + std::size_t(k)], p[k], 1e-5);
        const Vec3f n = world.model.normal(i), want = (R * model.normal(i).cast<double>()).cast<float>();
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(n[k], want[k], 1e-5);
        for (ModelParam kept : {ModelParam::Scaling, ModelParam::Opacity, ModelParam::Albedo})
            EXPECT_EQ(world.model.param(kept), model.param(kept));
    }
    EXPECT_EQ(orientation_rotation(ExportOrientation::None, up)(0, 0), 1.0);
    EXPECT_EQ(parse_export_orientation("y-up"), ExportOrientation::YUp);
    EXPECT_EQ(parse_export_orientation("none"), ExportOrientation::None);
    EXPECT_THROW(parse_export_orientation("z-up"), Error);
}

}  // namespace
}  // namespace lumigauss
