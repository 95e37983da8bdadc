// Surfel orientations from SfM points: the symmetric eigen solver, the quaternion of a normal, the normals of
// a noisy plane, and the k-nearest-neighbour indices they are built on.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "lumigauss/math/quaternion.h"
#include "lumigauss/model/knn.h"
#include "lumigauss/model/point_normals.h"
#include "lumigauss/train/gaussian_model.h"

namespace lumigauss {
namespace {

TEST(PointNormals, SmallestEigenvectorOfKnownMatrices) {
    const Vec3d d = smallest_eigenvector(Mat3d{{{3, 0, 0}, {0, 1, 0}, {0, 0, 2}}});
    EXPECT_NEAR(std::abs(d.y), 1.0, 1e-12);
    // R diag(5, 0.1, 2) R^T: the eigenvector of 0.1 is R's second column.
    const Mat3d r = rotation_from_unit_quaternion(normalize_quaternion(Vec4<double>{0.9, 0.2, -0.3, 0.4}));
    Mat3d a{};
    const double l[3] = {5, 0.1, 2};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) a(i, j) += r(i, k) * l[k] * r(j, k);
    const Vec3d e = smallest_eigenvector(a);
    EXPECT_NEAR(std::abs(dot(e, r.col(1))), 1.0, 1e-9);
}

TEST(PointNormals, SymmetricEigenSolvesTheEigenEquationInAscendingOrder) {
    const Mat3d r = rotation_from_unit_quaternion(normalize_quaternion(Vec4<double>{0.3, -0.5, 0.2, 0.7}));
    const double l[3] = {4, -1, 0.5};
    Mat3d a{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) a(i, j) += r(i, k) * l[k] * r(j, k);
    const SymmetricEigen e = symmetric_eigen(a);
    EXPECT_NEAR(e.values[0], -1, 1e-10);
    EXPECT_NEAR(e.values[1], 0.5, 1e-10);
    EXPECT_NEAR(e.values[2], 4, 1e-10);
    for (int i = 0; i < 3; ++i) {
        const Vec3d av = a * e.vectors[std::size_t(i)];
        for (int k = 0; k < 3; ++k)
            EXPECT_NEAR(av[k], e.values[std::size_t(i)] * e.vectors[std::size_t(i)][k], 1e-9);
        EXPECT_NEAR(length(e.vectors[std::size_t(i)]), 1.0, 1e-12);
    }
}

TEST(PointNormals, QuaternionTurnsZOntoTheNormal) {
    for (const Vec3d n : {Vec3d{0, 0, 1}, Vec3d{0, 0, -1}, Vec3d{1, 0, 0}, Vec3d{0.3, -0.4, 0.866}}) {
        const Vec3d u = (1.0 / length(n)) * n;
        const Mat3d r = rotation_from_unit_quaternion(quaternion_with_normal(u));
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(r.col(2)[k], u[k], 1e-12);
    }
}

TEST(PointNormals, NoisyPlaneGivesItsNormal) {
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> u(-5, 5);
    std::normal_distribution<float> noise(0, 0.02f);
    std::vector<Vec3f> pts;
    for (int i = 0; i < 2000; ++i) pts.push_back({u(rng), u(rng), 1.0f + noise(rng)});  // the plane z = 1
    const std::vector<Vec3f> n = point_normals(pts, 16);
    int good = 0;
    for (const Vec3f& v : n) good += std::abs(v.z) > 0.95f;
    EXPECT_GT(good, 1900);
}

TEST(PointNormals, KnnIndicesAreTheNearest) {
    const std::vector<Vec3f> pts = {{0, 0, 0}, {1, 0, 0}, {3, 0, 0}, {6, 0, 0}};
    const std::vector<std::uint32_t> idx = knn_indices(pts, 2);
    ASSERT_EQ(idx.size(), 8u);
    EXPECT_EQ(idx[0], 1u);
    EXPECT_EQ(idx[1], 2u);
    EXPECT_EQ(idx[6], 2u);  // point 3's nearest: 2, then 1
    EXPECT_EQ(idx[7], 1u);
    const std::vector<std::uint32_t> lone = knn_indices({{1, 2, 3}}, 3);
    EXPECT_EQ(lone, (std::vector<std::uint32_t>{0, 0, 0}));
}

TEST(PointNormals, ModelInitialisedFromPointsLiesInTheirPlane) {
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> u(-5, 5);
    std::vector<Vec3f> pts, rgb;
    for (int i = 0; i < 500; ++i) pts.push_back({u(rng), u(rng), 0.0f}), rgb.push_back({0.5f, 0.5f, 0.5f});
    const GaussianModel flat = GaussianModel::from_points(pts, rgb, 1.0, 7, {}, true);
    const GaussianModel random = GaussianModel::from_points(pts, rgb, 1.0, 7, {}, false);
    const auto upright = [](const GaussianModel& m) {
        int count = 0;
        const auto& q = m.param(ModelParam::Rotation);
        for (std::size_t i = 0; i < m.size(); ++i) {
            const Mat3d r = rotation_from_unit_quaternion(
                normalize_quaternion(Vec4<double>{q[4 * i], q[4 * i + 1], q[4 * i + 2], q[4 * i + 3]}));
            count += std::abs(r(2, 2)) < 0.5;  // the normal more than 60 degrees from the plane's
        }
        return count;
    };
    EXPECT_EQ(upright(flat), 0);
    EXPECT_GT(upright(random), 100);
}

}  // namespace
}  // namespace lumigauss
