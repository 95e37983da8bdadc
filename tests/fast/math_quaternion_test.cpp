// Quaternion conventions shared by COLMAP poses, surfel orientations and the synthetic generator.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "lumigauss/math/quaternion.h"

namespace lumigauss {
namespace {

void expect_round_trip(const Mat3d& r) {
    const Vec4<double> q = quaternion_from_rotation(r);
    EXPECT_GE(q.x, 0.0) << "w is kept non-negative";
    EXPECT_NEAR(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w, 1.0, 1e-12);
    const Mat3d back = rotation_from_unit_quaternion(q);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) EXPECT_NEAR(back(i, j), r(i, j), 1e-12);
}

TEST(MathQuaternion, RotationRoundTripOnRandomRotations) {
    std::mt19937 rng(5);
    std::normal_distribution<double> g(0, 1);
    for (int k = 0; k < 200; ++k)
        expect_round_trip(rotation_from_unit_quaternion(
            normalize_quaternion(Vec4<double>{g(rng), g(rng), g(rng), g(rng)})));
}

TEST(MathQuaternion, EveryPivotBranchIncludingHalfTurns) {
    // Half turns about x, y and z have trace -1 and pivot on each diagonal entry in turn; the identity pivots
    // on the trace.
    expect_round_trip(Mat3d::identity());
    expect_round_trip({{{1, 0, 0}, {0, -1, 0}, {0, 0, -1}}});
    expect_round_trip({{{-1, 0, 0}, {0, 1, 0}, {0, 0, -1}}});
    expect_round_trip({{{-1, 0, 0}, {0, -1, 0}, {0, 0, 1}}});
}

TEST(MathQuaternion, HamiltonConventionAsColmap) {
    // A quarter turn about +z, (w, x, y, z) = (cos 45, 0, 0, sin 45), takes +x to +y.
    const double h = std::sqrt(0.5);
    const Mat3d r = rotation_from_unit_quaternion(Vec4<double>{h, 0, 0, h});
    const Vec3d y = r * Vec3d{1, 0, 0};
    EXPECT_NEAR(y.x, 0.0, 1e-15);
    EXPECT_NEAR(y.y, 1.0, 1e-15);
}

}  // namespace
}  // namespace lumigauss
