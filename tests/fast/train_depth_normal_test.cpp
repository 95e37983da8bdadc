// Expected depth, normal from depth, normal consistency and distortion: known answers on planes and finite
// differences of every backward in double precision.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "lumigauss/train/depth_normal.h"

namespace lumigauss {
namespace {

std::vector<double> random_values(std::size_t n, double lo, double hi, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(lo, hi);
    std::vector<double> v(n);
    for (double& x : v) x = u(rng);
    return v;
}

Mat3d rotation_xy(double ax, double ay) {
    const Mat3d rx{{{1, 0, 0}, {0, std::cos(ax), -std::sin(ax)}, {0, std::sin(ax), std::cos(ax)}}};
    const Mat3d ry{{{std::cos(ay), 0, std::sin(ay)}, {0, 1, 0}, {-std::sin(ay), 0, std::cos(ay)}}};
    return rx * ry;
}

// A 13x11 camera, rotated and off the origin, with an off-centre principal point.
Camera test_camera() {
    Camera c;
    c.width = 13, c.height = 11;
    c.fx = 14, c.fy = 15, c.cx = 6.1, c.cy = 5.7;
    c.rotation = rotation_xy(0.3, -0.4);
    c.translation = {0.5, -0.2, 1.5};
    return c;
}

// z-depth of every pixel centre's ray hitting the plane dot(n, X) = offset (world space).
std::vector<double> plane_depth(const Camera& c, Vec3d n, double offset) {
    std::vector<double> depth(std::size_t(c.width) * c.height);
    const Vec3d o = c.center();
    for (int y = 0; y < c.height; ++y) {
        for (int x = 0; x < c.width; ++x) {
            const Vec3d ray =
                transpose(c.rotation) * Vec3d{(x + 0.5 - c.cx) / c.fx, (y + 0.5 - c.cy) / c.fy, 1.0};
            depth[std::size_t(y) * c.width + x] = (offset - dot(n, o)) / dot(n, ray);
        }
    }
    return depth;
}

TEST(TrainDepthNormal, PlaneGivesConstantCameraFacingNormal) {
    const Camera cam = test_camera();
    // A tilted plane in front of the camera: through the point 3 units along the optical axis.
    const Vec3d axis = transpose(cam.rotation) * Vec3d{0, 0, 1};
    const Vec3d on_plane = cam.center() + 3.0 * axis;
    for (const Vec3d dir : {Vec3d{0.2, -0.3, 1.0}, Vec3d{-0.2, -0.1, -1.0}}) {
        const Vec3d n = normalize(dir);
        const auto depth = plane_depth(cam, n, dot(n, on_plane));
        std::vector<double> normal(3 * depth.size());
        depth_to_normal<double>(cam, depth, normal);
        // The plane normal, oriented towards the camera.
        const Vec3d facing = dot(n, cam.center() - on_plane) > 0 ? n : -n;
        for (int y = 0; y < cam.height; ++y) {
            for (int x = 0; x < cam.width; ++x) {
                const std::size_t p = std::size_t(y) * cam.width + x;
                const Vec3d got{normal[3 * p], normal[3 * p + 1], normal[3 * p + 2]};
                const bool border = x == 0 || y == 0 || x == cam.width - 1 || y == cam.height - 1;
                const Vec3d want = border ? Vec3d{} : facing;
                EXPECT_NEAR(got.x, want.x, 1e-9) << x << "," << y;
                EXPECT_NEAR(got.y, want.y, 1e-9) << x << "," << y;
                EXPECT_NEAR(got.z, want.z, 1e-9) << x << "," << y;
            }
        }
    }
}

TEST(TrainDepthNormal, FrontoParallelPlaneFacesMinusZ) {
    Camera cam = test_camera();
    cam.rotation = Mat3d::identity(), cam.translation = {};
    const std::vector<double> depth(std::size_t(cam.width) * cam.height, 2.5);
    std::vector<double> normal(3 * depth.size());
    depth_to_normal<double>(cam, depth, normal);
    const std::size_t p = std::size_t(5) * cam.width + 6;
    EXPECT_NEAR(normal[3 * p], 0.0, 1e-12);
    EXPECT_NEAR(normal[3 * p + 1], 0.0, 1e-12);
    EXPECT_NEAR(normal[3 * p + 2], -1.0, 1e-12);
}

TEST(TrainDepthNormal, ExpectedDepthZeroAlphaIsZeroWithoutGradient) {
    const std::vector<double> depth{0.0, 1.0, 2.0}, alpha{0.0, 0.5, 0.25};
    std::vector<double> e(3);
    expected_depth<double>(depth, alpha, e);
    EXPECT_EQ(e, (std::vector<double>{0.0, 2.0, 8.0}));
    std::vector<double> gd(3, 0.0), ga(3, 0.0);
    expected_depth_backward<double>(depth, alpha, std::vector<double>{1, 1, 1}, gd, ga);
    EXPECT_EQ(gd[0], 0.0);
    EXPECT_EQ(ga[0], 0.0);
    EXPECT_DOUBLE_EQ(gd[1], 2.0);   // 1 / alpha
    EXPECT_DOUBLE_EQ(ga[1], -4.0);  // -D / alpha^2
    EXPECT_DOUBLE_EQ(ga[2], -32.0);
}

// Random but well-conditioned maps: a bumpy surface at depth ~3, alpha away from 0, random normals.
RasterImages<double> random_maps(const Camera& cam, unsigned seed) {
    RasterImages<double> img;
    img.width = cam.width, img.height = cam.height, img.channels = 3;
    const std::size_t n = std::size_t(cam.width) * cam.height;
    img.alpha = random_values(n, 0.3, 1.0, seed);
    const auto expected = random_values(n, 2.8, 3.2, seed + 1);
    img.depth.resize(n);
    for (std::size_t p = 0; p < n; ++p) img.depth[p] = expected[p] * img.alpha[p];
    img.normal = random_values(3 * n, -1, 1, seed + 2);
    img.distortion = random_values(n, 0, 0.1, seed + 3);
    return img;
}

std::vector<double> random_mask(std::size_t n, unsigned seed) {
    auto m = random_values(n, -0.5, 1.5, seed);
    for (double& v : m) v = std::min(1.0, std::max(0.0, v));
    return m;
}

// Central differences of L through one map of the images.
void expect_map_gradient(const Camera& cam, RasterImages<double> img,
                         std::vector<double> RasterImages<double>::*map, const std::vector<double>& mask,
                         const std::vector<double>& analytic, const char* name) {
    const double step = 1e-6, weight = 0.05;
    std::vector<double>& v = img.*map;
    ASSERT_EQ(analytic.size(), v.size()) << name;
    for (std::size_t i = 0; i < v.size(); ++i) {
        const double keep = v[i];
        v[i] = keep + step;
        const double up = normal_consistency_loss<double>(cam, img, mask, 0.0, nullptr);
        v[i] = keep - step;
        const double down = normal_consistency_loss<double>(cam, img, mask, 0.0, nullptr);
        v[i] = keep;
        const double fd = weight * (up - down) / (2 * step);
        EXPECT_NEAR(analytic[i], fd, 1e-7 * (1 + std::abs(fd)) + 1e-10) << name << " " << i;
    }
}

TEST(TrainDepthNormal, NormalLossGradientMatchesFiniteDifferences) {
    const Camera cam = test_camera();
    for (const bool masked : {false, true}) {
        const RasterImages<double> img = random_maps(cam, 50);
        const auto mask =
            masked ? random_mask(std::size_t(cam.width) * cam.height, 60) : std::vector<double>{};
        RasterImageGrads<double> grads;
        normal_consistency_loss<double>(cam, img, mask, 0.05, &grads);
        expect_map_gradient(cam, img, &RasterImages<double>::depth, mask, grads.depth, "depth");
        // Finite differences also see alpha's detached factor in (m N_rend) . (m N_d alpha), which the
        // backward rightly leaves out: add it back, d/d(alpha) = -m^2 N_rend . N_d / pixels.
        const std::size_t n = img.alpha.size();
        std::vector<double> surf_depth(n), surf_normal(3 * n), alpha_total = grads.alpha;
        expected_depth<double>(img.depth, img.alpha, surf_depth);
        depth_to_normal<double>(cam, surf_depth, surf_normal);
        for (std::size_t p = 0; p < n; ++p) {
            const double m = mask.empty() ? 1.0 : mask[p];
            double nn = 0;
            for (int c = 0; c < 3; ++c) nn += img.normal[3 * p + c] * surf_normal[3 * p + c];
            alpha_total[p] -= 0.05 * m * m * nn / double(n);
        }
        expect_map_gradient(cam, img, &RasterImages<double>::alpha, mask, alpha_total, "alpha");
        expect_map_gradient(cam, img, &RasterImages<double>::normal, mask, grads.normal, "normal");
    }
}

TEST(TrainDepthNormal, NormalLossKnownValues) {
    const Camera cam = test_camera();
    RasterImages<double> img = random_maps(cam, 70);
    const std::size_t n = img.alpha.size();
    // Rendered normal = alpha * (depth normal): each interior pixel gives 1 - alpha^2; the border gives 1.
    std::vector<double> surf_depth(n), surf_normal(3 * n);
    expected_depth<double>(img.depth, img.alpha, surf_depth);
    depth_to_normal<double>(cam, surf_depth, surf_normal);
    double want = 0;
    for (std::size_t p = 0; p < n; ++p) {
        for (int c = 0; c < 3; ++c) img.normal[3 * p + c] = img.alpha[p] * surf_normal[3 * p + c];
        const bool interior =
            surf_normal[3 * p] != 0 || surf_normal[3 * p + 1] != 0 || surf_normal[3 * p + 2] != 0;
        want += interior ? 1 - img.alpha[p] * img.alpha[p] : 1.0;
    }
    EXPECT_NEAR(normal_consistency_loss<double>(cam, img, {}, 1.0, nullptr), want / double(n), 1e-12);
    // A zero mask makes every pixel the constant 1, with no gradient.
    const std::vector<double> zero(n, 0.0);
    RasterImageGrads<double> grads;
    EXPECT_NEAR(normal_consistency_loss<double>(cam, img, zero, 1.0, &grads), 1.0, 1e-15);
    for (double g : grads.normal) EXPECT_EQ(g, 0.0);
    for (double g : grads.depth) EXPECT_EQ(g, 0.0);
}

TEST(TrainDepthNormal, FloatMatchesDoubleAndIsDeterministic) {
    Camera cam = test_camera().resized(131, 97);
    const RasterImages<double> d = random_maps(cam, 80);
    RasterImages<float> f;
    f.width = d.width, f.height = d.height, f.channels = 3;
    f.depth.assign(d.depth.begin(), d.depth.end());
    f.alpha.assign(d.alpha.begin(), d.alpha.end());
    f.normal.assign(d.normal.begin(), d.normal.end());
    const double ref = normal_consistency_loss<double>(cam, d, {}, 1.0, nullptr);
    RasterImageGrads<float> g1, g2;
    const float a = normal_consistency_loss<float>(cam, f, {}, 1.0f, &g1);
    const float b = normal_consistency_loss<float>(cam, f, {}, 1.0f, &g2);
    EXPECT_NEAR(a, ref, 1e-5);
    EXPECT_EQ(a, b);
    EXPECT_EQ(g1.depth, g2.depth);
    EXPECT_EQ(g1.alpha, g2.alpha);
    EXPECT_EQ(g1.normal, g2.normal);
}

TEST(TrainDepthNormal, DistortionLossIsMaskedMean) {
    const Camera cam = test_camera();
    const RasterImages<double> img = random_maps(cam, 90);
    const auto mask = random_mask(img.distortion.size(), 91);
    double want = 0;
    for (std::size_t p = 0; p < mask.size(); ++p) want += mask[p] * img.distortion[p];
    want /= double(mask.size());
    RasterImageGrads<double> grads;
    EXPECT_NEAR(distortion_loss<double>(img, mask, 100.0, &grads), want, 1e-15);
    for (std::size_t p = 0; p < mask.size(); ++p)
        EXPECT_DOUBLE_EQ(grads.distortion[p], 100.0 * mask[p] / double(mask.size()));
}

}  // namespace
}  // namespace lumigauss
