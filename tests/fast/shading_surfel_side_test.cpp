// Which side of a two-sided surfel a camera sees (shading/surfel_side.h): the official camera-facing rule,
// and the grazing rule of the default presets, in which a level surfel seen within a few degrees of its plane
// shows its upper side. Known answers for a ground surfel tilted away from a far, low camera (the case that
// drew dark blobs in the near ground of new views), the same surfel from steep views and a wall (unchanged),
// the backward through the side the rule picks by finite differences, and the renderers that take a run's
// rule.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "lumigauss/cameras/orbit.h"
#include "lumigauss/model/render_model.h"
#include "lumigauss/model/view_shading.h"
#include "lumigauss/relight/relit_render.h"
#include "lumigauss/shading/surfel_shading.h"
#include "lumigauss/shading/surfel_side.h"
#include "lumigauss/train/gaussian_model.h"
#include "lumigauss/train/view_shading_backward.h"
#include "support/finite_difference.h"
#include "support/random_surfels.h"

namespace lumigauss {
namespace {

double radians(double degrees) {
    return degrees * std::numbers::pi / 180.0;
}

// A camera at `eye` looking at the origin, z up.
Camera camera_at(Vec3d eye, int size = 40, double focal = 36) {
    Camera intrinsics = testing::test_camera(size, size);
    intrinsics.fx = intrinsics.fy = focal;
    intrinsics.cx = intrinsics.cy = 0.5 * size;
    return look_at(intrinsics, eye, {0, 0, 0}, {0, 0, 1});
}

// Raw parameters of `tilts.size()` surfels at `centres`, each level but turned by tilts[i] degrees about x
// (axis (0, -sin, cos): tilted towards -y), scale exp(log_scale), opacity 0.9, grey albedo 0.5, transfer sets
// with channel-0 DC 1 (positive) and 0.5 (negative) so that the side in use shows in the shadowed colour.
GaussianModel tilted_surfels(const std::vector<Vec3d>& centres, const std::vector<double>& tilts,
                             double log_scale = -1.0) {
    const std::size_t n = centres.size();
    std::vector<std::vector<float>> raw(kModelParamCount);
    for (int p = 0; p < kModelParamCount; ++p)
        raw[std::size_t(p)].assign(n * std::size_t(GaussianModel::width(ModelParam(p))), 0.0f);
    for (std::size_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) raw[int(ModelParam::Xyz)][3 * i + std::size_t(k)] = float(centres[i][k]);
        const double half = 0.5 * radians(tilts[i]);
        const float q[4] = {float(std::cos(half)), float(std::sin(half)), 0.0f, 0.0f};  // (w, x, y, z)
        for (int k = 0; k < 4; ++k) raw[int(ModelParam::Rotation)][4 * i + std::size_t(k)] = q[k];
        for (int k = 0; k < 2; ++k) raw[int(ModelParam::Scaling)][2 * i + std::size_t(k)] = float(log_scale);
        raw[int(ModelParam::Opacity)][i] = 2.2f;
        raw[int(ModelParam::TransferPositive)][i * kTransferStored] = 1.0f;
        raw[int(ModelParam::TransferNegative)][i * kTransferStored] = 0.5f;
    }
    return GaussianModel::from_raw(std::move(raw), 1.0);
}

// More light from above than from below (an outdoor sky over a darker ground).
ShCoeffs<float> sky_over_ground() {
    ShCoeffs<float> env;
    for (int c = 0; c < 3; ++c) {
        env.c[0][c] = 2.0f;
        env.c[2][c] = 1.0f;  // Y_10 ~ z
    }
    return env;
}

const SurfelSideRule kGrazing5{{0, 0, 1}, 5.0f};

// ---- sees_positive_side

TEST(SurfelSide, OfficialRuleIsTheSideFacingTheCamera) {
    for (float axis_up : {-1.0f, -0.95f, 0.0f, 0.5f, 0.95f, 1.0f}) {
        EXPECT_TRUE(sees_positive_side(0.01f, 10.0f, axis_up, 0.0f));
        EXPECT_TRUE(sees_positive_side(0.0f, 10.0f, axis_up, 0.0f));  // >= 0, as officially
        EXPECT_FALSE(sees_positive_side(-0.01f, 10.0f, axis_up, 0.0f));
    }
    EXPECT_FALSE(SurfelSideRule{}.active());
    EXPECT_EQ(SurfelSideRule{}.grazing_sine(), 0.0f);
}

TEST(SurfelSide, GrazingRuleShowsTheUpperSideOfLevelSurfelsOnly) {
    const float sine = kGrazing5.grazing_sine();
    EXPECT_NEAR(sine, std::sin(radians(5)), 1e-7);
    // Level (|axis . up| > 0.9), seen within 5 deg of the plane: the upper side, whichever way it faces.
    EXPECT_TRUE(sees_positive_side(-0.08f, 1.0f, 0.99f, sine));
    EXPECT_FALSE(sees_positive_side(0.08f, 1.0f, -0.99f, sine));
    EXPECT_TRUE(sees_positive_side(-0.8f, 10.0f, 0.91f, sine));
    // Outside the grazing band, or not level (a wall, a roof of 30 deg): the side facing the camera.
    EXPECT_FALSE(sees_positive_side(-0.09f, 1.0f, 0.99f, sine));
    EXPECT_TRUE(sees_positive_side(0.09f, 1.0f, -0.99f, sine));
    EXPECT_FALSE(sees_positive_side(-0.01f, 1.0f, 0.0f, sine));
    EXPECT_FALSE(sees_positive_side(-0.01f, 1.0f, 0.86f, sine));
}

// ---- compute_view_normals

// The case of the dark near-ground blobs (bench/RESULTS.md, session 36): a ground surfel tilted 4 deg away
// from a camera 34 m off at 1.55 m height shows that camera its underside; its camera-facing normal points
// down and shades it with the light from below.
TEST(SurfelSideNormals, GroundTiltedAwayFromALowFarCameraShowsItsUpperSideUnderTheRule) {
    const GaussianModel m = tilted_surfels({{0, 0, 0}}, {4.0});
    const Camera low = camera_at({0, 34, 1.55});  // on the +y side: the axis (0, -0.07, 1) tilts away
    ViewNormals official, grazing;
    compute_view_normals(m, low, official);
    compute_view_normals(m, low, grazing, kGrazing5);
    EXPECT_EQ(official.positive_side[0], 0);
    EXPECT_LT(official.normal[0].z, -0.99f);  // the underside: lit from below
    EXPECT_EQ(grazing.positive_side[0], 1);
    EXPECT_GT(grazing.normal[0].z, 0.99f);
    EXPECT_NEAR(grazing.normal[0].y, -std::sin(radians(4)), 1e-6);
    // With the up turned over, the same surfel's upper side is its negative one.
    ViewNormals flipped_up;
    compute_view_normals(m, low, flipped_up, SurfelSideRule{{0, 0, -1}, 5.0f});
    EXPECT_EQ(flipped_up.positive_side[0], 0);
}

TEST(SurfelSideNormals, SteepViewsAndWallsKeepTheCameraFacingSide) {
    // The same ground surfel from 45 deg above (its upper side) and from 30 deg below (its underside), and a
    // wall (tilted 90 deg, axis -y) seen nearly edge-on from the side: every rule agrees with the official.
    const GaussianModel ground = tilted_surfels({{0, 0, 0}}, {4.0});
    const GaussianModel wall = tilted_surfels({{0, 0, 0}}, {90.0});
    struct Case {
        const GaussianModel* model;
        Vec3d eye;
        int positive;
    };
    for (const Case& c : {Case{&ground, {0, 10, 10}, 1}, Case{&ground, {0, 10, -6}, 0},
                          Case{&wall, {34, 1.0, 1.5}, 0}, Case{&wall, {34, -1.0, 1.5}, 1}}) {
        const Camera cam = camera_at(c.eye);
        for (const SurfelSideRule& rule : {SurfelSideRule{}, kGrazing5}) {
            ViewNormals vn;
            compute_view_normals(*c.model, cam, vn, rule);
            EXPECT_EQ(vn.positive_side[0], c.positive) << c.eye.x << " " << c.eye.y << " " << c.eye.z;
        }
    }
}

// ---- the backward through the side the rule picks

// L = sum_j w_j colour_j, normals recomputed under the rule (as a perturbation would).
double weighted_colours(const GaussianModel& m, const Camera& cam, const ShCoeffs<float>& env,
                        const std::vector<float>& w) {
    ViewNormals vn;
    compute_view_normals(m, cam, vn, kGrazing5);
    SurfelBatch<float> b;
    shade_surfels(m, env, ShadingMode::Both, vn, b);
    double l = 0;
    for (std::size_t j = 0; j < b.colors.size(); ++j) l += double(w[j]) * double(b.colors[j]);
    return l;
}

TEST(SurfelSideBackward, TheUpperSideSeenFromBelowMatchesFiniteDifferences) {
    // Ground surfels tilted 3-4.5 deg away from a camera 2.6 deg above their plane: each is seen 0.6-1.9 deg
    // from below, inside the 5 deg band, so the rule shows the upper side, and the finite-difference steps
    // (a few hundredths of a degree) never cross a decision.
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Vec3d> centres;
    std::vector<double> tilts;
    for (int i = 0; i < 6; ++i) {
        centres.push_back({-3.0 + 6.0 * u(rng), -1.0 + 2.0 * u(rng), 0.0});
        tilts.push_back(3.0 + 1.5 * u(rng));
    }
    GaussianModel model = tilted_surfels(centres, tilts);
    const Camera cam = camera_at({0, 34, 1.55});
    const ShCoeffs<float> env = sky_over_ground();
    std::vector<float> w(model.size() * kSurfelColourChannels);
    for (float& v : w) v = float(u(rng) - 0.3);

    ViewNormals vn;
    compute_view_normals(model, cam, vn, kGrazing5);
    ViewNormals official;
    compute_view_normals(model, cam, official);
    for (std::size_t i = 0; i < model.size(); ++i) {
        ASSERT_EQ(vn.positive_side[i], 1) << i;
        ASSERT_EQ(official.positive_side[i], 0) << i;  // the case the rule changes
    }
    model.zero_grad();
    (void)shade_surfels_backward(model, env, ShadingMode::Both, vn, w);
    const auto loss = [&] { return weighted_colours(model, cam, env, w); };
    for (ModelParam p : {ModelParam::Rotation, ModelParam::TransferPositive, ModelParam::TransferNegative,
                         ModelParam::Albedo}) {
        std::vector<float>& values = model.param(p);
        for (std::size_t j = 0; j < values.size(); ++j) {
            if (p != ModelParam::Rotation && p != ModelParam::Albedo && j % kTransferStored != 0) continue;
            const double fd = testing::central_difference(values[j], 1e-3, loss);
            const double analytic = model.grad(p)[j];
            EXPECT_NEAR(analytic, fd, 1e-2 * std::max(std::fabs(fd), std::fabs(analytic)) + 3e-4)
                << SurfelModel::name(p) << " [" << j << "]";
        }
    }
    // The negative (lower) side is not in use: no gradient reaches it.
    for (float g : model.grad(ModelParam::TransferNegative)) EXPECT_EQ(g, 0.0f);
}

// ---- the renderers take the run's rule

TEST(SurfelSideRenderers, RelitAndModelRenderersShadeTheRunsSide) {
    // A large ground surfel tilted 2.5 deg away from a camera 5 m off, 1 deg above its plane: under the
    // rule it shows its upper side, lit from above, so every covered pixel is brighter than officially.
    const GaussianModel model = tilted_surfels({{0, 0, 0}}, {2.5}, std::log(2.0));
    const Camera cam = camera_at({0, 5, 5 * std::tan(radians(1.0))}, 64, 400);
    const ShCoeffs<float> env = sky_over_ground();
    RelitRenderer official(model), grazing(model, RasterBackend::Cpu, kGrazing5);
    const RasterImages<float> a = official.render(cam, env);
    const RasterImages<float> b = grazing.render(cam, env);
    double covered = 0, brighter = 0;
    for (std::size_t p = 0; p < a.alpha.size(); ++p) {
        if (a.alpha[p] < 0.1f) continue;
        ++covered;
        const float* ca = &a.color[p * kRelitChannels];
        const float* cb = &b.color[p * kRelitChannels];
        EXPECT_EQ(a.alpha[p], b.alpha[p]);
        if (cb[kRelitUnshadowed] > ca[kRelitUnshadowed] * 1.05f && cb[kRelitShadowed] > ca[kRelitShadowed])
            ++brighter;
    }
    EXPECT_GT(covered, 20);
    EXPECT_EQ(brighter, covered);

    ModelRenderer renderer(RasterBackend::Cpu, kGrazing5);
    renderer.render(model, cam, env, ShadingMode::Unshadowed);
    EXPECT_EQ(renderer.normals().positive_side[0], 1);
    const RasterImages<float> c =
        render_with_environment(model, cam, env, ShadingMode::Unshadowed, RasterBackend::Cpu, kGrazing5);
    for (std::size_t p = 0; p < c.alpha.size(); ++p)
        EXPECT_NEAR(c.color[3 * p], b.color[p * kRelitChannels + kRelitUnshadowed], 1e-5f) << p;
}

}  // namespace
}  // namespace lumigauss
