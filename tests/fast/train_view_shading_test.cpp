// Shading of a whole surfel model for one camera (model/view_shading.h, its backward
// train/view_shading_backward.h): the camera-facing normal rule of the official compute_normal_world_space
// (research/lumigauss_official.md 2.1), colours equal to the single-surfel functions of
// shading/surfel_shading.h in every mode, and the backward into the raw albedo, raw quaternion, channel 0 of
// the transfer sets and the environment, by central finite differences.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <span>
#include <utility>
#include <vector>

#include "lumigauss/math/quaternion.h"
#include "lumigauss/model/render_model.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/shading/surfel_shading.h"
#include "lumigauss/train/gaussian_model.h"
#include "lumigauss/train/view_shading_backward.h"
#include "lumigauss/util/error.h"
#include "support/finite_difference.h"
#include "support/random_surfels.h"

namespace lumigauss {
namespace {

using testing::central_difference;
double uni(std::mt19937_64& rng, double lo = -1.0, double hi = 1.0) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
}

Vec3d axis_of(Vec4f raw_q) {
    const Mat3d r =
        rotation_from_unit_quaternion(normalize_quaternion(Vec4<double>{raw_q.x, raw_q.y, raw_q.z, raw_q.w}));
    return r.col(2);
}

Vec4f raw_quat(const GaussianModel& m, std::size_t i) {
    const auto& q = m.param(ModelParam::Rotation);
    return {q[4 * i], q[4 * i + 1], q[4 * i + 2], q[4 * i + 3]};
}

Vec3d mean_of(const GaussianModel& m, std::size_t i) {
    const auto& x = m.param(ModelParam::Xyz);
    return Vec3f{x[3 * i], x[3 * i + 1], x[3 * i + 2]}.cast<double>();
}

struct ModelOptions {
    std::size_t count = 20;
    // Minimum |cos| between the surfel axis and the direction to the camera: keeps every surfel away from
    // the (piecewise constant) side flip, so that finite differences of the rotation never cross it.
    double min_facing = 0.25;
    // Depth range in camera space; a negative minimum also puts surfels behind the camera.
    double min_depth = 2.0, max_depth = 6.0;
};

// Random raw parameters: unnormalised quaternions (norms 0.3..3), albedo activations in (0.2, 0.8) (away
// from the max(0, .) clamp), transfer sets whose channel-0 DC is about 1 (shadowed light well above the
// 1e-5 floor under bright_env), all 27 stored values random so that a wrong channel would show.
std::vector<std::vector<float>> random_raw(const Camera& cam, std::uint64_t seed,
                                           const ModelOptions& o = {}) {
    std::mt19937_64 rng(seed);
    const std::size_t n = o.count;
    std::vector<std::vector<float>> raw(kModelParamCount);
    for (int p = 0; p < kModelParamCount; ++p)
        raw[std::size_t(p)].assign(n * std::size_t(GaussianModel::width(ModelParam(p))), 0.0f);
    auto& xyz = raw[int(ModelParam::Xyz)];
    auto& rot = raw[int(ModelParam::Rotation)];
    auto& scl = raw[int(ModelParam::Scaling)];
    auto& opa = raw[int(ModelParam::Opacity)];
    auto& alb = raw[int(ModelParam::Albedo)];
    auto& tp = raw[int(ModelParam::TransferPositive)];
    auto& tn = raw[int(ModelParam::TransferNegative)];
    const Vec3d center = cam.center();
    const Mat3d rt = transpose(cam.rotation);
    for (std::size_t i = 0; i < n; ++i) {
        const double z = uni(rng, o.min_depth, o.max_depth);
        const Vec3d p_cam{uni(rng) * 0.6 * z, uni(rng) * 0.6 * z, z};
        const Vec3d p = rt * (p_cam - cam.translation);
        for (int k = 0; k < 3; ++k) xyz[3 * i + std::size_t(k)] = float(p[k]);
        const Vec3d p_f = Vec3f{float(p.x), float(p.y), float(p.z)}.cast<double>();  // as stored
        for (;;) {
            const Vec4<double> q{uni(rng), uni(rng), uni(rng), uni(rng)};
            const double len = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
            if (len < 0.2) continue;
            const double s = uni(rng, 0.3, 3.0) / len;
            const Vec4f qf{float(s * q.x), float(s * q.y), float(s * q.z), float(s * q.w)};
            const double cos = dot(axis_of(qf), normalize(center - p_f));
            if (std::fabs(cos) < o.min_facing) continue;
            for (int k = 0; k < 4; ++k) rot[4 * i + std::size_t(k)] = qf[k];
            break;
        }
        for (int k = 0; k < 2; ++k) scl[2 * i + std::size_t(k)] = float(uni(rng, -3.0, -1.0));
        opa[i] = float(uni(rng, -2.0, 2.0));
        for (int c = 0; c < 3; ++c)
            alb[3 * i + std::size_t(c)] = float((uni(rng, 0.2, 0.8) - 0.5) / sh_const::kY00);
        for (auto* t : {&tp, &tn}) {
            for (int k = 0; k < kTransferStored; ++k)
                (*t)[i * kTransferStored + std::size_t(k)] = float(0.2 * uni(rng));
            (*t)[i * kTransferStored] = float(1.0 + 0.2 * uni(rng));
        }
    }
    return raw;
}

GaussianModel random_model(const Camera& cam, std::uint64_t seed, const ModelOptions& o = {}) {
    return GaussianModel::from_raw(random_raw(cam, seed, o), 1.0);
}

// Rows [begin, end) of raw model arrays.
std::vector<std::vector<float>> slice_raw(const std::vector<std::vector<float>>& raw, std::size_t begin,
                                          std::size_t end) {
    std::vector<std::vector<float>> out(raw.size());
    for (int p = 0; p < kModelParamCount; ++p) {
        const auto w = std::size_t(GaussianModel::width(ModelParam(p)));
        const auto& v = raw[std::size_t(p)];
        out[std::size_t(p)].assign(v.begin() + std::ptrdiff_t(begin * w),
                                   v.begin() + std::ptrdiff_t(end * w));
    }
    return out;
}

// Irradiance and shadowed light comfortably above the 1e-5 floor for unit normals and the transfers above.
ShCoeffs<float> bright_env(std::mt19937_64& rng) {
    ShCoeffs<float> env;
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) env.c[k][c] = float(0.2 * uni(rng));
    for (int c = 0; c < 3; ++c) env.c[0][c] += 3.0f;
    return env;
}

std::vector<float> random_weights(std::mt19937_64& rng, std::size_t n) {
    std::vector<float> w(n);
    for (float& v : w) v = float(uni(rng));
    return w;
}

// L = sum_j w_j colour_j for the model as seen from `cam` (normals recomputed, as a perturbation would).
double weighted_colour_sum(const GaussianModel& m, const Camera& cam, const ShCoeffs<float>& env,
                           ShadingMode mode, const std::vector<float>& w) {
    ViewNormals vn;
    compute_view_normals(m, cam, vn);
    SurfelBatch<float> b;
    shade_surfels(m, env, mode, vn, b);
    double l = 0;
    for (std::size_t j = 0; j < b.colors.size(); ++j) l += double(w[j]) * double(b.colors[j]);
    return l;
}

constexpr double kStep = 2e-3;
constexpr double kRelTol = 1e-2;
constexpr double kAbsTol = 3e-4;

void expect_grad(double analytic, double fd, const char* what, std::size_t index) {
    EXPECT_NEAR(analytic, fd, kRelTol * std::max(std::fabs(fd), std::fabs(analytic)) + kAbsTol)
        << what << " [" << index << "]";
}

bool all_zero(std::span<const float> v) {
    return std::all_of(v.begin(), v.end(), [](float x) { return x == 0.0f; });
}

// ---------------------------------------------------------------------------------------------------------
// compute_view_normals

TEST(TrainViewShadingNormals, KnownAnswerIdentityCamera) {
    // Camera at the origin looking along +z; surfel at (0, 0, 5).
    Camera cam = testing::test_camera();
    cam.rotation = Mat3d::identity();
    cam.translation = {0, 0, 0};
    std::vector<std::vector<float>> raw(kModelParamCount);
    for (int p = 0; p < kModelParamCount; ++p)
        raw[std::size_t(p)].assign(2 * std::size_t(GaussianModel::width(ModelParam(p))), 0.0f);
    raw[int(ModelParam::Xyz)] = {0, 0, 5, 0.5f, 0, 5};
    // Surfel 0: identity rotation scaled by 7 (unnormalised): axis +z points away from the camera, so the
    // official cos = -(W n).p_view = -5 < 0: negative side, normal flipped to -z.
    // Surfel 1: 180 degrees about x, raw (0, 0.3, 0, 0): axis -z already faces the camera: positive side.
    raw[int(ModelParam::Rotation)] = {7, 0, 0, 0, 0, 0.3f, 0, 0};
    const GaussianModel m = GaussianModel::from_raw(std::move(raw), 1.0);
    ViewNormals vn;
    vn.normal.assign(5, Vec3f{9, 9, 9});  // stale content of another size must be replaced
    compute_view_normals(m, cam, vn);
    ASSERT_EQ(vn.normal.size(), 2u);
    ASSERT_EQ(vn.positive_side.size(), 2u);
    EXPECT_EQ(vn.positive_side[0], 0);
    EXPECT_EQ(vn.positive_side[1], 1);
    for (int s = 0; s < 2; ++s) {
        EXPECT_NEAR(vn.normal[std::size_t(s)].x, 0.0f, 1e-6f);
        EXPECT_NEAR(vn.normal[std::size_t(s)].y, 0.0f, 1e-6f);
        EXPECT_NEAR(vn.normal[std::size_t(s)].z, -1.0f, 1e-6f);
    }
}

TEST(TrainViewShadingNormals, UnitFacingCameraAndMatchOfficialRule) {
    const Camera cam = testing::test_camera();
    ModelOptions o;
    o.count = 300;
    o.min_facing = 0.0;  // every orientation, flips included
    o.min_depth = -4.0;  // also behind the camera (the rule does not care)
    const GaussianModel m = random_model(cam, 21, o);
    ViewNormals vn;
    compute_view_normals(m, cam, vn);
    ASSERT_EQ(vn.normal.size(), m.size());
    const Vec3d center = cam.center();
    int positive = 0, negative = 0, checked = 0;
    for (std::size_t i = 0; i < m.size(); ++i) {
        const Vec3d n = vn.normal[i].cast<double>();
        EXPECT_NEAR(length(n), 1.0, 1e-6) << i;
        const Vec3d axis = axis_of(raw_quat(m, i));  // R(q/|q|)[:,2]
        const Vec3d x = mean_of(m, i);
        // Official rule, evaluated in double: cos = -(W axis) . (W x + t).
        const double cos_official = -dot(cam.rotation * axis, cam.world_to_camera(x));
        // Its geometric form: axis . (camera centre - mean), the same number since W is a rotation.
        const double cos_geometric = dot(axis, center - x);
        EXPECT_NEAR(cos_official, cos_geometric, 1e-9 * (1 + length(center - x))) << i;
        if (std::fabs(cos_official) < 1e-4) continue;  // the float evaluation may decide either way
        ++checked;
        const bool expect_positive = cos_official >= 0;
        EXPECT_EQ(vn.positive_side[i], expect_positive ? 1 : 0) << i;
        (expect_positive ? positive : negative)++;
        const Vec3d expect_n = expect_positive ? axis : -axis;
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(n[k], expect_n[k], 2e-6) << i;
        EXPECT_GT(dot(n, center - x), 0.0) << i;  // faces the camera
    }
    EXPECT_GT(checked, 290);
    EXPECT_GT(positive, 50);
    EXPECT_GT(negative, 50);
}

// ---------------------------------------------------------------------------------------------------------
// shade_surfels

TEST(TrainViewShadingForward, ColoursEqualSingleSurfelFunctions) {
    const Camera cam = testing::test_camera();
    const GaussianModel m = random_model(cam, 31, {.count = 40, .min_facing = 0.0});
    std::mt19937_64 rng(32);
    const ShCoeffs<float> env = bright_env(rng);
    ViewNormals vn;
    compute_view_normals(m, cam, vn);

    SurfelBatch<float> un, sh, both;
    for (SurfelBatch<float>* b : {&un, &sh, &both}) b->channels = 17, b->colors.assign(3, -1.0f);
    shade_surfels(m, env, ShadingMode::Unshadowed, vn, un);
    shade_surfels(m, env, ShadingMode::Shadowed, vn, sh);
    shade_surfels(m, env, ShadingMode::Both, vn, both);
    EXPECT_EQ(shading_channels(ShadingMode::Unshadowed), 3);
    EXPECT_EQ(shading_channels(ShadingMode::Shadowed), 3);
    EXPECT_EQ(shading_channels(ShadingMode::Both), 6);
    EXPECT_EQ(un.channels, 3);
    EXPECT_EQ(sh.channels, 3);
    EXPECT_EQ(both.channels, 6);
    ASSERT_EQ(un.colors.size(), 3 * m.size());
    ASSERT_EQ(sh.colors.size(), 3 * m.size());
    ASSERT_EQ(both.colors.size(), 6 * m.size());

    int sides[2] = {0, 0};
    for (std::size_t i = 0; i < m.size(); ++i) {
        const auto& a = m.param(ModelParam::Albedo);
        const Vec3f albedo{a[3 * i], a[3 * i + 1], a[3 * i + 2]};
        float pos[kTransferCoeffs], neg[kTransferCoeffs];
        for (int k = 0; k < kTransferCoeffs; ++k) {
            pos[k] = m.param(ModelParam::TransferPositive)[i * kTransferStored + std::size_t(3 * k)];
            neg[k] = m.param(ModelParam::TransferNegative)[i * kTransferStored + std::size_t(3 * k)];
        }
        const bool positive = vn.positive_side[i] != 0;
        ++sides[positive ? 1 : 0];
        const Vec3f u = surfel_colour_unshadowed(env, albedo, vn.normal[i]);
        const Vec3f s = surfel_colour_shadowed(env, albedo, pos, neg, positive);
        for (int c = 0; c < 3; ++c) {
            EXPECT_FLOAT_EQ(un.colors[3 * i + std::size_t(c)], u[c]) << i;
            EXPECT_FLOAT_EQ(sh.colors[3 * i + std::size_t(c)], s[c]) << i;
            // Both: shadowed in 0..2, unshadowed in 3..5, equal to the single modes.
            EXPECT_FLOAT_EQ(both.colors[6 * i + std::size_t(kShadowedOffset + c)],
                            sh.colors[3 * i + std::size_t(c)]);
            EXPECT_FLOAT_EQ(both.colors[6 * i + std::size_t(kUnshadowedOffset + c)],
                            un.colors[3 * i + std::size_t(c)]);
        }
        // Independent double-precision check of the official formula (3.2-3.4) for the unshadowed colour
        // and of the side selection for the shadowed one.
        const Vec3d nd = vn.normal[i].cast<double>();
        const Vec3d e = irradiance(env.cast<double>(), nd);
        double t_side[kShCount];
        for (int k = 0; k < kShCount; ++k) t_side[k] = double(positive ? pos[k] : neg[k]);
        const Vec3d sr = shadowed_radiance(t_side, env.cast<double>());
        for (int c = 0; c < 3; ++c) {
            const double alb = std::max(0.0, sh_const::kY00 * double(albedo[c]) + 0.5);
            const double cu = alb * std::pow(std::max(e[c], 1e-5), 1 / 2.2);
            const double cs = alb * std::pow(std::max(sr[c], 1e-5), 1 / 2.2);
            EXPECT_NEAR(un.colors[3 * i + std::size_t(c)], cu, 1e-5 * (1 + cu)) << i;
            EXPECT_NEAR(sh.colors[3 * i + std::size_t(c)], cs, 1e-5 * (1 + cs)) << i;
        }
    }
    EXPECT_GT(sides[0], 5);
    EXPECT_GT(sides[1], 5);
}

TEST(TrainViewShadingForward, CosineLobeTransferMatchesUnshadowed) {
    const Camera cam = testing::test_camera();
    GaussianModel m = random_model(cam, 41, {.count = 60, .min_facing = 0.0});
    std::mt19937_64 rng(42);
    const ShCoeffs<float> env = bright_env(rng);
    ViewNormals vn;
    compute_view_normals(m, cam, vn);
    // Channel 0 of the side in use := SH projection of max(0, n.w) at the camera-flipped normal; the
    // other side and the other channels := junk.
    for (std::size_t i = 0; i < m.size(); ++i) {
        const bool positive = vn.positive_side[i] != 0;
        auto& used = m.param(positive ? ModelParam::TransferPositive : ModelParam::TransferNegative);
        auto& other = m.param(positive ? ModelParam::TransferNegative : ModelParam::TransferPositive);
        float lobe[kShCount];
        cosine_lobe_sh(vn.normal[i], lobe);
        for (int k = 0; k < kTransferStored; ++k) {
            used[i * kTransferStored + std::size_t(k)] = float(5 * uni(rng));
            other[i * kTransferStored + std::size_t(k)] = float(5 * uni(rng));
        }
        for (int k = 0; k < kShCount; ++k) used[i * kTransferStored + std::size_t(3 * k)] = lobe[k];
    }
    SurfelBatch<float> un, sh;
    shade_surfels(m, env, ShadingMode::Unshadowed, vn, un);
    shade_surfels(m, env, ShadingMode::Shadowed, vn, sh);
    for (std::size_t j = 0; j < un.colors.size(); ++j)
        EXPECT_NEAR(sh.colors[j], un.colors[j], 1e-5f * std::fabs(un.colors[j])) << j;

    // With the sides swapped the lobe is on the wrong set and the colours must differ.
    ViewNormals swapped = vn;
    for (auto& s : swapped.positive_side) s = s ? 0 : 1;
    SurfelBatch<float> wrong;
    shade_surfels(m, env, ShadingMode::Shadowed, swapped, wrong);
    int differ = 0;
    for (std::size_t j = 0; j < un.colors.size(); ++j)
        differ += std::fabs(wrong.colors[j] - un.colors[j]) > 1e-3f * std::fabs(un.colors[j]);
    EXPECT_GT(differ, int(un.colors.size()) / 2);
}

TEST(TrainViewShadingForward, SizeMismatchesThrow) {
    const Camera cam = testing::test_camera();
    GaussianModel m = random_model(cam, 51, {.count = 5});
    std::mt19937_64 rng(52);
    const ShCoeffs<float> env = bright_env(rng);
    ViewNormals vn;
    compute_view_normals(m, cam, vn);
    SurfelBatch<float> b;
    ViewNormals short_vn = vn;
    short_vn.normal.pop_back(), short_vn.positive_side.pop_back();
    EXPECT_THROW(shade_surfels(m, env, ShadingMode::Both, short_vn, b), Error);
    const std::vector<float> g(3 * m.size(), 1.0f);  // 3 per surfel, but Both needs 6
    EXPECT_THROW(shade_surfels_backward(m, env, ShadingMode::Both, vn, g), Error);
}

TEST(TrainViewShadingForward, EmptyModel) {
    const Camera cam = testing::test_camera();
    GaussianModel m = random_model(cam, 53, {.count = 0});
    ViewNormals vn;
    compute_view_normals(m, cam, vn);
    EXPECT_TRUE(vn.normal.empty());
    SurfelBatch<float> b;
    const ShCoeffs<float> env{};
    shade_surfels(m, env, ShadingMode::Both, vn, b);
    EXPECT_TRUE(b.colors.empty());
    const ShCoeffs<float> g = shade_surfels_backward(m, env, ShadingMode::Both, vn, {});
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) EXPECT_EQ(g.c[k][c], 0.0f);
}

// ---------------------------------------------------------------------------------------------------------
// shade_surfels_backward

void check_backward_by_finite_differences(ShadingMode mode, std::uint64_t seed) {
    const Camera cam = testing::test_camera();
    GaussianModel model = random_model(cam, seed);
    const GaussianModel& cm = model;
    std::mt19937_64 rng(seed + 1);
    ShCoeffs<float> env = bright_env(rng);
    const std::size_t n = model.size();
    const int channels = shading_channels(mode);
    const std::vector<float> w = random_weights(rng, n * std::size_t(channels));

    model.zero_grad();
    ViewNormals vn;
    compute_view_normals(model, cam, vn);
    int sides[2] = {0, 0};
    for (auto s : vn.positive_side) ++sides[s ? 1 : 0];
    EXPECT_GT(sides[0], 2);
    EXPECT_GT(sides[1], 2);
    const ShCoeffs<float> g_env = shade_surfels_backward(model, env, mode, vn, w);
    const auto loss = [&] { return weighted_colour_sum(model, cam, env, mode, w); };

    // Raw albedo.
    EXPECT_TRUE(cm.has_grad(ModelParam::Albedo));
    for (std::size_t j = 0; j < 3 * n; ++j)
        expect_grad(cm.grad(ModelParam::Albedo)[j],
                    central_difference(model.param(ModelParam::Albedo)[j], kStep, loss), "albedo", j);

    // Raw quaternion, through the camera-flipped normal (only the unshadowed term depends on it).
    const bool unshadowed = mode != ShadingMode::Shadowed;
    EXPECT_EQ(cm.has_grad(ModelParam::Rotation), unshadowed);
    if (unshadowed) {
        for (std::size_t j = 0; j < 4 * n; ++j)
            expect_grad(cm.grad(ModelParam::Rotation)[j],
                        central_difference(model.param(ModelParam::Rotation)[j], kStep, loss), "rotation", j);
    } else {
        EXPECT_TRUE(all_zero(cm.grad(ModelParam::Rotation)));
    }

    // Transfer sets: channel 0 of the side in use; channels 1, 2 and the other side get exactly zero.
    const bool shadowed = mode != ShadingMode::Unshadowed;
    for (ModelParam p : {ModelParam::TransferPositive, ModelParam::TransferNegative}) {
        EXPECT_EQ(cm.has_grad(p), shadowed);
        if (!shadowed) {
            EXPECT_TRUE(all_zero(cm.grad(p)));
            continue;
        }
        const bool positive_set = p == ModelParam::TransferPositive;
        for (std::size_t i = 0; i < n; ++i) {
            const bool in_use = (vn.positive_side[i] != 0) == positive_set;
            for (int k = 0; k < kTransferStored; ++k) {
                const std::size_t j = i * kTransferStored + std::size_t(k);
                const float g = cm.grad(p)[j];
                if (in_use && k % 3 == 0) {
                    expect_grad(g, central_difference(model.param(p)[j], kStep, loss), "transfer", j);
                } else {
                    EXPECT_EQ(g, 0.0f) << "transfer " << j << " (in use " << in_use << ", k " << k << ")";
                    if (k < 6) {
                        EXPECT_EQ(central_difference(model.param(p)[j], kStep, loss), 0.0) << j;
                    }
                }
            }
        }
    }

    // Environment (returned, not accumulated into the model).
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c)
            expect_grad(g_env.c[k][c], central_difference(env.c[k][c], kStep, loss), "env",
                        std::size_t(3 * k + c));

    // Geometry and opacity are not touched by shading.
    for (ModelParam p : {ModelParam::Xyz, ModelParam::Scaling, ModelParam::Opacity}) {
        EXPECT_FALSE(cm.has_grad(p));
        EXPECT_TRUE(all_zero(cm.grad(p)));
    }
}

TEST(TrainViewShadingBackward, UnshadowedMatchesFiniteDifferences) {
    check_backward_by_finite_differences(ShadingMode::Unshadowed, 61);
}

TEST(TrainViewShadingBackward, ShadowedMatchesFiniteDifferences) {
    check_backward_by_finite_differences(ShadingMode::Shadowed, 71);
}

TEST(TrainViewShadingBackward, BothMatchesFiniteDifferences) {
    check_backward_by_finite_differences(ShadingMode::Both, 81);
}

// Both mode's backward is the sum of the single modes' backwards on the matching channel slices.
TEST(TrainViewShadingBackward, BothIsSumOfSingleModes) {
    const Camera cam = testing::test_camera();
    GaussianModel both = random_model(cam, 91);
    GaussianModel un = random_model(cam, 91), sh = random_model(cam, 91);
    std::mt19937_64 rng(92);
    const ShCoeffs<float> env = bright_env(rng);
    const std::size_t n = both.size();
    const std::vector<float> w = random_weights(rng, 6 * n);
    std::vector<float> w_sh(3 * n), w_un(3 * n);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t c = 0; c < 3; ++c) {
            w_sh[3 * i + c] = w[6 * i + std::size_t(kShadowedOffset) + c];
            w_un[3 * i + c] = w[6 * i + std::size_t(kUnshadowedOffset) + c];
        }
    ViewNormals vn;
    compute_view_normals(both, cam, vn);
    const ShCoeffs<float> g_both = shade_surfels_backward(both, env, ShadingMode::Both, vn, w);
    const ShCoeffs<float> g_sh = shade_surfels_backward(sh, env, ShadingMode::Shadowed, vn, w_sh);
    const ShCoeffs<float> g_un = shade_surfels_backward(un, env, ShadingMode::Unshadowed, vn, w_un);
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(g_both.c[k][c], g_sh.c[k][c] + g_un.c[k][c], 1e-5f * (1 + std::fabs(g_both.c[k][c])));
    const GaussianModel &cb = both, &cs = sh, &cu = un;
    for (std::size_t j = 0; j < 3 * n; ++j)
        EXPECT_NEAR(cb.grad(ModelParam::Albedo)[j],
                    cs.grad(ModelParam::Albedo)[j] + cu.grad(ModelParam::Albedo)[j], 1e-6f);
    for (std::size_t j = 0; j < 4 * n; ++j)
        EXPECT_FLOAT_EQ(cb.grad(ModelParam::Rotation)[j], cu.grad(ModelParam::Rotation)[j]);
    for (ModelParam p : {ModelParam::TransferPositive, ModelParam::TransferNegative})
        for (std::size_t j = 0; j < n * kTransferStored; ++j) EXPECT_FLOAT_EQ(cb.grad(p)[j], cs.grad(p)[j]);
}

TEST(TrainViewShadingBackward, AccumulatesIntoGradientBuffers) {
    const Camera cam = testing::test_camera();
    GaussianModel m = random_model(cam, 101);
    std::mt19937_64 rng(102);
    const ShCoeffs<float> env = bright_env(rng);
    const std::vector<float> w = random_weights(rng, 6 * m.size());
    ViewNormals vn;
    compute_view_normals(m, cam, vn);
    shade_surfels_backward(m, env, ShadingMode::Both, vn, w);
    const GaussianModel& cm = m;
    std::vector<std::vector<float>> once;
    for (int p = 0; p < kModelParamCount; ++p) {
        const auto g = cm.grad(ModelParam(p));
        once.emplace_back(g.begin(), g.end());
    }
    shade_surfels_backward(m, env, ShadingMode::Both, vn, w);
    for (int p = 0; p < kModelParamCount; ++p)
        for (std::size_t j = 0; j < once[std::size_t(p)].size(); ++j)
            EXPECT_EQ(cm.grad(ModelParam(p))[j], 2.0f * once[std::size_t(p)][j]) << p << " " << j;
}

// The environment gradient is reduced in fixed chunks: the same bits with one thread or several, on a model
// large enough to have several chunks.
TEST(TrainViewShadingBackward, DeterministicAcrossThreadCounts) {
    const Camera cam = testing::test_camera();
    const ModelOptions o{.count = 10000, .min_facing = 0.0};
    std::mt19937_64 rng(112);
    const ShCoeffs<float> env = bright_env(rng);
    GaussianModel a = random_model(cam, 111, o), b = random_model(cam, 111, o);
    const std::vector<float> w = random_weights(rng, 6 * a.size());
    ViewNormals vn_a, vn_b;
    ShCoeffs<float> g_a, g_b;
    SurfelBatch<float> col_a, col_b;
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        compute_view_normals(a, cam, vn_a);
        shade_surfels(a, env, ShadingMode::Both, vn_a, col_a);
        g_a = shade_surfels_backward(a, env, ShadingMode::Both, vn_a, w);
    }
    {
        tbb::global_control several(tbb::global_control::max_allowed_parallelism, 4);
        compute_view_normals(b, cam, vn_b);
        shade_surfels(b, env, ShadingMode::Both, vn_b, col_b);
        g_b = shade_surfels_backward(b, env, ShadingMode::Both, vn_b, w);
    }
    EXPECT_EQ(vn_a.positive_side, vn_b.positive_side);
    EXPECT_EQ(col_a.colors, col_b.colors);
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) EXPECT_EQ(g_a.c[k][c], g_b.c[k][c]) << k << " " << c;
    const GaussianModel &ca = a, &cb = b;
    for (ModelParam p : {ModelParam::Albedo, ModelParam::Rotation, ModelParam::TransferPositive}) {
        const auto x = ca.grad(p), y = cb.grad(p);
        EXPECT_TRUE(std::equal(x.begin(), x.end(), y.begin(), y.end()));
    }
}

// The environment gradient sums every reduction chunk: on a model of several chunks it equals the sum of the
// gradients of its parts (each smaller than one chunk), and so do the per-surfel gradients.
TEST(TrainViewShadingBackward, EnvGradientSumsAllChunks) {
    const Camera cam = testing::test_camera();
    const ModelOptions o{.count = 10000, .min_facing = 0.0};
    const std::vector<std::vector<float>> raw = random_raw(cam, 121, o);
    std::mt19937_64 rng(122);
    const ShCoeffs<float> env = bright_env(rng);
    const std::vector<float> w = random_weights(rng, 6 * o.count);
    GaussianModel whole = GaussianModel::from_raw(raw, 1.0);
    ViewNormals vn;
    compute_view_normals(whole, cam, vn);
    const ShCoeffs<float> g_whole = shade_surfels_backward(whole, env, ShadingMode::Both, vn, w);
    ShCoeffs<double> g_parts{};
    double scale = 0;
    const std::size_t bounds[] = {0, 3000, 6000, 9000, 10000};
    for (int part = 0; part < 4; ++part) {
        const std::size_t b = bounds[part], e = bounds[part + 1];
        GaussianModel m = GaussianModel::from_raw(slice_raw(raw, b, e), 1.0);
        ViewNormals vp;
        compute_view_normals(m, cam, vp);
        const std::vector<float> wp(w.begin() + std::ptrdiff_t(6 * b), w.begin() + std::ptrdiff_t(6 * e));
        const ShCoeffs<float> g = shade_surfels_backward(m, env, ShadingMode::Both, vp, wp);
        for (int k = 0; k < kShCount; ++k)
            for (int c = 0; c < 3; ++c) {
                g_parts.c[k][c] += double(g.c[k][c]);
                scale = std::max(scale, std::fabs(double(g.c[k][c])));
            }
        const GaussianModel& cm = m;
        const GaussianModel& cw = whole;
        for (std::size_t j = 0; j < 3 * (e - b); ++j)
            ASSERT_EQ(cm.grad(ModelParam::Albedo)[j], cw.grad(ModelParam::Albedo)[3 * b + j]) << b + j / 3;
    }
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(double(g_whole.c[k][c]), g_parts.c[k][c], 1e-4 * scale) << k;
}

}  // namespace
}  // namespace lumigauss
