// The gt-env protocol (eval/gt_env.h): the light-scale fit (known answer, training photos only, the
// irradiance weighting), how directional the learned lights are, a model built from the tiny synthetic
// scene's ground-truth surfels (the scale it implies, its normal and albedo errors), invariance under the
// model's albedo/light gauge, and errors that name the missing file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>

#include "lumigauss/eval/gt_env.h"
#include "lumigauss/eval/report.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/io/image.h"
#include "lumigauss/model/lighting_mlp.h"
#include "lumigauss/model/relightable_ply.h"
#include "lumigauss/relight/relit_sky.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/sh_text.h"
#include "lumigauss/shading/sky_image.h"
#include "lumigauss/util/error.h"
#include "synth_test_util.h"

namespace lumigauss {
namespace {

namespace fs = std::filesystem;
using synth_test::TempDir;
using ::testing::HasSubstr;

ShCoeffs<double> random_sh(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    ShCoeffs<double> s;
    for (int j = 0; j < kShCount; ++j) s.c[j] = {u(rng), u(rng), u(rng)};
    s.c[0] = s.c[0] + Vec3d{3, 3, 3};
    return s;
}

ShCoeffs<double> scaled(const ShCoeffs<double>& s, double k) {
    ShCoeffs<double> r;
    for (int j = 0; j < kShCount; ++j) r.c[j] = s.c[j] * k;
    return r;
}

// ---- Light scale -----------------------------------------------------------------------------------------

TEST(EvalGtEnv, LightScaleKnownAnswer) {
    std::mt19937 rng(3);
    std::vector<ShCoeffs<double>> truth, learned;
    std::vector<double> exposure;
    const double k = 0.37;
    for (int i = 0; i < 6; ++i) {
        truth.push_back(random_sh(rng));
        exposure.push_back(0.75 + 0.1 * i);
        learned.push_back(scaled(truth.back(), k * exposure.back()));
    }
    const LightScaleFit fit = fit_light_scale(learned, truth, exposure);
    EXPECT_NEAR(fit.scale, k, 1e-12);
    EXPECT_NEAR(fit.relative_residual, 0.0, 1e-6);
    ASSERT_EQ(fit.per_photo.size(), 6u);
    for (double ki : fit.per_photo) EXPECT_NEAR(ki, k, 1e-12);

    // Noise perturbs it only a little; the residual reports it.
    std::normal_distribution<double> noise(0.0, 0.01);
    for (auto& l : learned)
        for (auto& c : l.c) c = c + Vec3d{noise(rng), noise(rng), noise(rng)};
    const LightScaleFit noisy = fit_light_scale(learned, truth, exposure);
    EXPECT_NEAR(noisy.scale, k, 0.01);
    EXPECT_GT(noisy.relative_residual, 1e-4);

    EXPECT_THROW(fit_light_scale({}, {}, {}), Error);
    EXPECT_THROW(fit_light_scale(learned, truth, {1.0}), Error);
}

// An SH light with luminance DC `dc` and the same band-1 vector `b1` on every channel.
ShCoeffs<double> dipole_light(double dc, Vec3d b1) {
    ShCoeffs<double> s{};
    s.c[0] = Vec3d{dc, dc, dc};
    for (int j = 1; j < 4; ++j) s.c[j] = Vec3d{b1[j - 1], b1[j - 1], b1[j - 1]};
    s.c[5] = Vec3d{0.2, 0.1, 0.3};  // band 2 does not enter
    return s;
}

TEST(EvalGtEnv, LightDirectionKnownAnswer) {
    const ShCoeffs<double> truth = dipole_light(3.0, {0.5, 1.0, -0.3});
    // A scaled copy is exactly as directional, in the same direction.
    LightDirection d = light_direction(scaled(truth, 0.4), truth);
    EXPECT_NEAR(d.strength, 1.0, 1e-12);
    EXPECT_NEAR(d.error_deg, 0.0, 1e-6);
    // Half the dipole for the same DC: half as directional.
    d = light_direction(dipole_light(3.0, {0.25, 0.5, -0.15}), truth);
    EXPECT_NEAR(d.strength, 0.5, 1e-12);
    EXPECT_NEAR(d.error_deg, 0.0, 1e-6);
    // A dipole at right angles: 90 deg, and a reversed one 180.
    d = light_direction(dipole_light(1.5, {1.0, -0.5, 0.0}), truth);
    EXPECT_NEAR(d.error_deg, 90.0, 1e-9);
    EXPECT_NEAR(light_direction(dipole_light(3.0, {-0.5, -1.0, 0.3}), truth).error_deg, 180.0, 1e-6);
    // No direction in the truth, or no light: undefined.
    EXPECT_TRUE(std::isnan(light_direction(truth, dipole_light(3.0, {0.01, 0.0, 0.0})).strength));
    EXPECT_TRUE(std::isnan(light_direction(dipole_light(0.0, {1, 0, 0}), truth).error_deg));
    // The fit's medians skip the undefined photos.
    const std::vector<ShCoeffs<double>> learned = {scaled(truth, 0.4), dipole_light(3.0, {0.25, 0.5, -0.15}),
                                                   dipole_light(3.0, {1, 1, 1})};
    const std::vector<ShCoeffs<double>> truths = {truth, truth, dipole_light(3.0, {0, 0, 0})};
    const LightScaleFit fit = fit_light_scale(learned, truths, {1.0, 1.0, 1.0});
    ASSERT_EQ(fit.direction.size(), 3u);
    EXPECT_NEAR(fit.median_direction_strength, 0.75, 1e-12);
    EXPECT_NEAR(fit.median_direction_error_deg, 0.0, 1e-6);
}

TEST(EvalGtEnv, LightScaleWeightsAreTheIrradianceIntegralOverTheSphere) {
    // sum_j A_l^2 L_j T_j == integral over the sphere of E[L](n) E[T](n), per channel (orthonormal SH).
    std::mt19937 rng(5);
    const ShCoeffs<double> l = random_sh(rng), t = random_sh(rng);
    double weighted = 0;
    for (int j = 0; j < kShCount; ++j) weighted += irradiance_weight(j) * l.c[j][1] * t.c[j][1];
    const int n = 200000;
    double integral = 0;
    const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {  // Fibonacci sphere: equal-area points
        const double z = 1.0 - (2.0 * i + 1.0) / n, r = std::sqrt(1 - z * z), phi = golden * i;
        const Vec3d dir{r * std::cos(phi), r * std::sin(phi), z};
        integral += irradiance(l, dir)[1] * irradiance(t, dir)[1];
    }
    integral *= 4 * std::numbers::pi / n;
    EXPECT_NEAR(integral / weighted, 1.0, 1e-4);
    EXPECT_DOUBLE_EQ(irradiance_weight(0), std::numbers::pi * std::numbers::pi);
    EXPECT_DOUBLE_EQ(irradiance_weight(8), std::numbers::pi * std::numbers::pi / 16);
}

TEST(EvalGtEnv, RunLightScaleUsesTrainingPhotosOnly) {
    TempDir tmp("eval_scale_train_only");
    std::mt19937 rng(9);
    const ShCoeffs<double> a = random_sh(rng), b = random_sh(rng);
    fs::create_directories(tmp / "env");
    write_sh_text(tmp / "env/a_sh.txt", a);
    write_sh_text(tmp / "env/b_sh.txt", b);
    GtSceneMeta meta;
    meta.root = tmp.str();
    meta.meta_path = tmp / "meta.json";
    meta.images = {{"train_0.png", "train", "a", 0.8},
                   {"train_1.png", "train", "b", 1.2},
                   {"test_0.png", "test", "b", 1.0}};
    RelightableRun run;
    const double k = 2.5;
    run.image_names = {"train_0.png", "test_0.png", "train_1.png", "not_in_meta.png"};
    run.learned_sh = {scaled(a, k * 0.8), scaled(b, 100.0), scaled(b, k * 1.2), scaled(a, -7.0)};
    const LightScaleFit fit = fit_run_light_scale(run, meta);
    EXPECT_NEAR(fit.scale, k, 1e-8);  // SH text keeps 9 digits
    EXPECT_EQ(fit.names, (std::vector<std::string>{"train_0.png", "train_1.png"}));
    // A photo evaluated as a test view is excluded even where meta.json calls it a training photo.
    EXPECT_EQ(fit_run_light_scale(run, meta, {"train_1.png"}).names,
              (std::vector<std::string>{"train_0.png"}));

    run.image_names = {"test_0.png", "x.png", "y.png", "z.png"};
    try {
        fit_run_light_scale(run, meta);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_THAT(e.what(), HasSubstr("meta.json"));
    }
    // A missing SH file is named.
    meta.images.push_back({"train_2.png", "train", "c", 1.0});
    run.image_names = {"train_2.png", "x.png", "y.png", "z.png"};
    try {
        fit_run_light_scale(run, meta);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_THAT(e.what(), HasSubstr((fs::path(tmp.str()) / "env" / "c_sh.txt").string()));
    }
}

// ---- The tiny synthetic scene -----------------------------------------------------------------------------

const std::string& tiny_scene() {
    static TempDir dir("eval_gt_env_scene");
    static const std::string root = [] {
        synth::generate_synthetic_scene(synth_test::tiny_options(dir.str()));
        return dir.str();
    }();
    return root;
}

// A run whose model is the ground-truth surfels (albedo (rho/pi)^(1/2.2), unoccluded transfer) and whose
// learned SH of training photo i is light_scale * exposure_i * true SH_i, with the albedo divided by
// light_scale^(1/2.2) so that the model still renders the training photos as with light scale 1 (the gauge).
RelightableRun oracle_run(const std::string& root, double light_scale) {
    RelightableRun run;
    run.model = relightable_from_surfels(load_2dgs_ply(root + "/gt/surfels.ply"));
    const double c = std::pow(light_scale, -1 / 2.2);
    for (float& raw : run.model.param(ModelParam::Albedo))
        raw = float((c * (sh_const::kY00 * raw + 0.5) - 0.5) / sh_const::kY00);
    const GtSceneMeta meta = load_gt_scene_meta(root);
    const Dataset scene = load_dataset(root);
    for (const View* v : scene.split(Split::Train)) {
        const GtImageMeta* m = meta.find(v->name);
        EXPECT_NE(m, nullptr) << v->name;
        run.image_names.push_back(v->name);
        run.learned_sh.push_back(scaled(load_condition_sh(meta, m->condition), light_scale * m->exposure));
    }
    return run;
}

TEST(EvalGtEnv, GroundTruthSurfelsScoreWell) {
    const std::string& root = tiny_scene();
    const RelightableRun run = oracle_run(root, 0.6);
    const Dataset scene = load_dataset(root);
    const GtEnvResult r = evaluate_gt_env(run, scene, load_gt_scene_meta(root));
    EXPECT_NEAR(r.light.scale, 0.6, 1e-8);
    EXPECT_NEAR(r.light.relative_residual, 0.0, 1e-6);
    // The learned lights are the true ones (up to k and exposure): no residual on the part the photos see
    // either. The reference lights, fitted to the photos' shading, see only part of each light.
    ASSERT_TRUE(r.light_reference.has_value());
    EXPECT_EQ(r.light_reference->photos, int(scene.split(Split::Train).size()));
    EXPECT_NEAR(r.light_reference->learned_seen_residual, 0.0, 1e-6);
    EXPECT_GE(r.light_reference->min_seen, 1);
    EXPECT_LE(r.light_reference->median_seen, 9);
    EXPECT_GE(r.light_reference->unseen_share, 0.0);
    EXPECT_LT(r.light_reference->unseen_share, 1.0);
    EXPECT_GT(r.light_reference->reference_residual, 0.0);
    EXPECT_LT(r.light_reference->reference_seen_residual, 1.0);
    ASSERT_EQ(r.images.size(), scene.split(Split::Test).size());
    ASSERT_TRUE(r.gt_mask);
    ASSERT_TRUE(r.has_albedo);
    ASSERT_TRUE(r.has_normal);
    // Perfect geometry: the rendered normals are the true ones except at edges between faces, where
    // surfels blend (at 64x48 pixels edges are many: measured mean 9.7, median 0.7 degrees).
    EXPECT_LT(r.mean_normal.median_deg, 2.0);
    EXPECT_LT(r.mean_normal.mean_deg, 15.0);
    EXPECT_LT(r.pooled_normal.median_deg, 2.0);
    // The model's albedo is (rho/pi)^(1/2.2) / 0.6^(1/2.2) (the gauge of oracle_run): the linear scale to
    // gt/albedo is 0.6 pi, the gamma one (0.6 pi)^(1/2.2), up to the surfels' texture averaging and the
    // pixel they widen bright pillars by (measured 0.92 to 0.98 of it linear, 0.97 to 1.0 gamma).
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(r.albedo_scale[c] / (0.6 * std::numbers::pi), 1.0, 0.12) << c;
        EXPECT_NEAR(r.albedo_gamma_scale[c] / std::pow(0.6 * std::numbers::pi, 1 / 2.2), 1.0, 0.05) << c;
    }
    EXPECT_GT(r.mean_albedo.psnr, 17.0);        // measured 20.2
    EXPECT_GT(r.mean_albedo_gamma.psnr, 20.0);  // measured 23.4
    // Lit as the photos up to gamma 2.2 instead of sRGB, missing shadows, the sun's SH truncation and the
    // ray tracer's noise (measured 20.3 dB, SSIM 0.43 on 64x48 pixels).
    EXPECT_GT(r.mean_unshadowed.psnr, 17.0);
    EXPECT_GT(r.mean_unshadowed.ssim, 0.3);
    for (const GtEnvImageResult& im : r.images) {
        EXPECT_GT(im.mask_pixels, 100u);
        EXPECT_EQ(im.exposure, 1.0);
        EXPECT_EQ(im.panels.truth.width, im.panels.shadowed.width);
        EXPECT_FALSE(im.panels.albedo.empty());
        EXPECT_LE(im.shadowed.ssim, 1.0);
        // Unoccluded transfer: shadowed == unshadowed.
        EXPECT_NEAR(im.shadowed.psnr, im.unshadowed.psnr, 0.05);
    }

    // The report holds every key.
    const nlohmann::ordered_json j = gt_env_metrics_json(r, {"run", root});
    for (const char* key : {"protocol", "light_scale", "albedo_scale", "images", "mean", "normal_all_pixels"})
        EXPECT_TRUE(j.contains(key)) << key;
    EXPECT_EQ(j["images"].size(), r.images.size());
    EXPECT_TRUE(j["images"][0]["shadowed"].contains("ssim"));
    EXPECT_TRUE(j["mean"]["normal"].contains("median_deg"));
    EXPECT_TRUE(j["light_scale"]["reference"].contains("learned_seen_residual"));
    const Image sheet = gt_env_contact_sheet(r.images[0]);
    EXPECT_EQ(sheet.width, 6 * scene.views[0].camera.width + 10);
    EXPECT_EQ(sheet.height, 2 * scene.views[0].camera.height + 2);
}

TEST(EvalGtEnv, MetricsAreInvariantUnderTheAlbedoLightGauge) {
    // albedo * c with learned light * c^(-2.2) renders every training photo identically; the fitted scale
    // absorbs it, so every metric must be unchanged.
    const std::string& root = tiny_scene();
    const Dataset scene = load_dataset(root);
    const GtSceneMeta meta = load_gt_scene_meta(root);
    const double c = 1.3;
    GtEnvOptions opt;
    opt.keep_panels = false;
    const GtEnvResult ra = evaluate_gt_env(oracle_run(root, 1.0), scene, meta, opt);
    const GtEnvResult rb = evaluate_gt_env(oracle_run(root, std::pow(c, -2.2)), scene, meta, opt);
    EXPECT_NEAR(rb.light.scale, std::pow(c, -2.2), 1e-8);
    EXPECT_NEAR(ra.mean_shadowed.psnr, rb.mean_shadowed.psnr, 1e-3);
    EXPECT_NEAR(ra.mean_unshadowed.ssim, rb.mean_unshadowed.ssim, 1e-4);
    EXPECT_NEAR(ra.mean_albedo.psnr, rb.mean_albedo.psnr, 1e-3);
    EXPECT_NEAR(ra.mean_albedo_gamma.psnr, rb.mean_albedo_gamma.psnr, 1e-3);
    EXPECT_NEAR(ra.mean_normal.mean_deg, rb.mean_normal.mean_deg, 1e-6);
    for (int ch = 0; ch < 3; ++ch) {  // the albedo scales absorb c
        EXPECT_NEAR(rb.albedo_gamma_scale[ch] * c / ra.albedo_gamma_scale[ch], 1.0, 1e-4);
        EXPECT_NEAR(rb.albedo_scale[ch] * std::pow(c, 2.2) / ra.albedo_scale[ch], 1.0, 1e-4);
    }
    // The reference comes from the scene alone; the seen residual of the learned lights absorbs c like k.
    ASSERT_TRUE(ra.light_reference && rb.light_reference);
    EXPECT_EQ(ra.light_reference->reference_residual, rb.light_reference->reference_residual);
    EXPECT_NEAR(ra.light_reference->learned_seen_residual, rb.light_reference->learned_seen_residual, 1e-6);
    opt.light_reference = false;
    EXPECT_FALSE(evaluate_gt_env(oracle_run(root, 1.0), scene, meta, opt).light_reference.has_value());
}

// The image-space light scale (header, step 8) follows the per-channel colour gauge that one scalar k cannot:
// albedo_c * g_c with light_c * g_c^(-2.2) renders every training photo the same for any g per channel, so
// the fitted k_c must move by exactly g_c^(-2.2) and the image-scaled scores must not move, while the
// headline (one k from the learned lights) sees a colour cast.
TEST(EvalGtEnv, ImageLightScaleFollowsTheColourGauge) {
    const std::string& root = tiny_scene();
    const Dataset scene = load_dataset(root);
    const GtSceneMeta meta = load_gt_scene_meta(root);
    const RelightableRun plain = oracle_run(root, 1.0);
    RelightableRun tinted = plain;
    const std::array<double, 3> g{0.8, 1.0, 1.25};
    std::vector<float>& albedo = tinted.model.param(ModelParam::Albedo);
    for (std::size_t i = 0; i < albedo.size(); ++i) {
        const double c = g[i % 3];  // the albedo is RGB per surfel
        albedo[i] = float((c * (sh_const::kY00 * albedo[i] + 0.5) - 0.5) / sh_const::kY00);
    }
    const std::array<double, 3> k_plain = fit_image_light_scale(plain, scene, meta, {}).value();
    const std::array<double, 3> k_tinted = fit_image_light_scale(tinted, scene, meta, {}).value();
    for (std::size_t c = 0; c < 3; ++c) {
        EXPECT_NEAR(k_tinted[c] / k_plain[c], std::pow(g[c], -2.2), 1e-4) << c;
        EXPECT_NEAR(k_plain[c], 1.0, 0.25) << "the true surfels under the true light need about k = 1";
    }
    GtEnvOptions opt;
    opt.keep_panels = false;
    const GtEnvResult a = evaluate_gt_env(plain, scene, meta, opt);
    const GtEnvResult b = evaluate_gt_env(tinted, scene, meta, opt);
    ASSERT_TRUE(a.image_scaled && b.image_scaled);
    EXPECT_NEAR(a.mean_image_scaled_shadowed.psnr, b.mean_image_scaled_shadowed.psnr, 1e-3);
    EXPECT_GT(a.mean_shadowed.psnr, b.mean_shadowed.psnr + 0.5) << "one k cannot undo a colour cast";
    opt.image_light_scale = false;
    EXPECT_FALSE(evaluate_gt_env(plain, scene, meta, opt).image_scaled);
}

// Step 9: the evaluated pixels split by the true normal. The true surfels under the true light need about
// the same gain on both kinds of surface; the same model with every surfel that does not face up darkened to
// 0.8 of its albedo (display value) needs 1/0.8 more there and nothing more on the ground.
TEST(EvalGtEnv, BySurfaceFindsWallsDarkerThanTheGround) {
    const std::string& root = tiny_scene();
    const Dataset scene = load_dataset(root);
    const GtSceneMeta meta = load_gt_scene_meta(root);
    GtEnvOptions opt;
    opt.keep_panels = false;
    opt.image_light_scale = false;
    const RelightableRun truth = oracle_run(root, 1.0);
    RelightableRun dark_walls = truth;
    std::vector<float>& albedo = dark_walls.model.param(ModelParam::Albedo);
    for (std::size_t i = 0; i < dark_walls.model.size(); ++i) {
        if (std::abs(dark_walls.model.normal(i).z) > 0.9f) continue;
        for (int c = 0; c < 3; ++c) {
            float& raw = albedo[3 * i + std::size_t(c)];
            raw = float((0.8 * (sh_const::kY00 * raw + 0.5) - 0.5) / sh_const::kY00);
        }
    }
    const GtEnvResult a = evaluate_gt_env(truth, scene, meta, opt);
    const GtEnvResult b = evaluate_gt_env(dark_walls, scene, meta, opt);
    ASSERT_TRUE(a.has_normal);
    ASSERT_GT(a.surfaces.up.pixels, 200u);
    ASSERT_GT(a.surfaces.other.pixels, 200u);
    EXPECT_EQ(a.surfaces.up.pixels, b.surfaces.up.pixels);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(a.surfaces.up.gain(c), 1.0, 0.3) << c;
        EXPECT_NEAR(a.surfaces.other.gain(c), 1.0, 0.3) << c;
        EXPECT_NEAR(b.surfaces.up.gain(c) / a.surfaces.up.gain(c), 1.0, 0.03) << c;
        EXPECT_NEAR(b.surfaces.other.gain(c) / a.surfaces.other.gain(c), 1.25, 0.06) << c;
    }
    // The ground keeps its score up to the edges where wall surfels blend into it; the walls' score moves
    // (up here: without shadows the true surfels' walls are brighter than the photos, gain about 0.8).
    EXPECT_NEAR(a.surfaces.up.psnr(), b.surfaces.up.psnr(), 0.5);
    EXPECT_GT(std::abs(b.surfaces.other.psnr() - a.surfaces.other.psnr()), 1.0);
    const nlohmann::ordered_json j = gt_env_metrics_json(b, {"run", root});
    EXPECT_TRUE(j["mean"]["by_surface"]["other"].contains("gain_rgb"));
}

TEST(EvalGtEnv, AWrongLightScaleScoresWorse) {
    // The same model with its learned light 4x too bright for every photo (training photos included) no
    // longer renders its training photos; the fitted k follows the learned light, so the test renders are
    // too bright too and the protocol must score it lower.
    const std::string& root = tiny_scene();
    const Dataset scene = load_dataset(root);
    const GtSceneMeta meta = load_gt_scene_meta(root);
    GtEnvOptions opt;
    opt.keep_panels = false;
    RelightableRun bright = oracle_run(root, 1.0);
    for (auto& sh : bright.learned_sh) sh = scaled(sh, 4.0);
    const GtEnvResult good = evaluate_gt_env(oracle_run(root, 1.0), scene, meta, opt);
    const GtEnvResult worse = evaluate_gt_env(bright, scene, meta, opt);
    EXPECT_NEAR(worse.light.scale, 4.0, 1e-8);
    EXPECT_GT(good.mean_unshadowed.psnr, worse.mean_unshadowed.psnr + 3.0);
}

// The empty-pixel diagnostic: the true surfels cover the evaluated pixels (the mask is gt/mask eroded, so
// none of them is an edge), and the same surfels faded to nothing leave every one empty, with no covered
// PSNR.
TEST(EvalGtEnv, EmptyPixelsAreCountedOverTheEvaluationMask) {
    const std::string& root = tiny_scene();
    const Dataset scene = load_dataset(root);
    const GtSceneMeta meta = load_gt_scene_meta(root);
    GtEnvOptions opt;
    opt.keep_panels = false;
    const GtEnvResult full = evaluate_gt_env(oracle_run(root, 1.0), scene, meta, opt);
    EXPECT_LT(full.empty_fraction, 0.01);
    EXPECT_NEAR(full.mean_covered_shadowed_psnr, full.mean_shadowed.psnr, 0.5);
    RelightableRun faded = oracle_run(root, 1.0);
    for (float& logit : faded.model.param(ModelParam::Opacity)) logit = -20.0f;
    const GtEnvResult none = evaluate_gt_env(faded, scene, meta, opt);
    EXPECT_EQ(none.empty_fraction, 1.0);
    EXPECT_TRUE(std::isnan(none.mean_covered_shadowed_psnr));
    EXPECT_FALSE(none.image_scaled) << "no covered training pixel: no image-space light scale";
    for (const GtEnvImageResult& im : none.images) EXPECT_EQ(im.empty_fraction, 1.0) << im.name;
    EXPECT_TRUE(gt_env_metrics_json(none, {"run", root})["mean"].contains("empty"));
}

// A run trained with its sky behind the surfels is shown over the condition's own panorama (not its
// degree-2 SH, which rings around a sun), scaled as the light is, and ending below the run's horizon.
TEST(EvalGtEnv, TheSkyBehindIsTheTruePanoramaAboveTheHorizon) {
    const std::string& root = tiny_scene();
    const Dataset scene = load_dataset(root);
    const GtSceneMeta meta = load_gt_scene_meta(root);
    RelightableRun empty = oracle_run(root, 0.7);
    for (float& logit : empty.model.param(ModelParam::Opacity)) logit = -30.0f;
    empty.sky_background = true;
    empty.sky_horizon = {{0, 0, 1}, 4, 4};
    GtEnvOptions opt;
    opt.image_light_scale = false;
    const GtEnvResult r = evaluate_gt_env(empty, scene, meta, opt);
    const std::vector<const View*> views = scene.split(Split::Test);
    ASSERT_EQ(r.images.size(), views.size());
    int above = 0, below = 0, differs_from_sh = 0;
    for (std::size_t i = 0; i < views.size(); ++i) {
        const GtImageMeta& im = *meta.find(views[i]->name);
        const Image panorama = read_image(root + "/env/" + im.condition + ".exr");
        PanoramaSky sky;
        sky.pixels = &panorama;
        sky.factor = Vec3d{1, 1, 1} * (r.light.scale * im.exposure);
        sky.horizon = empty.sky_horizon;
        const Image expected = panorama_sky_image(views[i]->camera, sky);
        ShCoeffs<float> env =
            scaled(load_condition_sh(meta, im.condition), r.light.scale * im.exposure).cast<float>();
        const Image sh_sky = sky_image(views[i]->camera, env, nullptr, empty.sky_horizon);
        const Image& shown = r.images[i].panels.shadowed;
        ASSERT_EQ(shown.pixels.size(), expected.pixels.size());
        for (std::size_t q = 0; q < shown.pixels.size(); ++q) {
            EXPECT_NEAR(shown.pixels[q], std::min(1.0f, expected.pixels[q]), 1e-5f) << q;
            differs_from_sh += std::abs(expected.pixels[q] - sh_sky.pixels[q]) > 0.05f;
        }
        for (int y = 0; y < views[i]->camera.height; ++y) {
            const double z = pixel_ray_direction(views[i]->camera, 10, y).z;
            if (z > 0.05) above += shown.at(10, y, 0) > 0.0f;
            if (z < -0.15) {
                ++below;
                EXPECT_EQ(shown.at(10, y, 0), 0.0f);
            }
        }
    }
    EXPECT_GT(above, 0);
    EXPECT_GT(below, 0);
    EXPECT_GT(differs_from_sh, 0) << "the panorama and its SH should differ somewhere";
}

TEST(EvalGtEnv, WorksWithoutGroundTruthImages) {
    // Only meta.json and env/*_sh.txt are required: without gt/ the mask is the scene's own (eroded), and
    // albedo and normal metrics are left out.
    TempDir tmp("eval_no_gt");
    const std::string root = tmp / "scene";
    fs::copy(tiny_scene(), root, fs::copy_options::recursive);
    fs::remove_all(root + "/gt/albedo");
    fs::remove_all(root + "/gt/normal");
    fs::remove_all(root + "/gt/mask");
    GtEnvOptions opt;
    opt.keep_panels = false;
    const GtEnvResult r =
        evaluate_gt_env(oracle_run(tiny_scene(), 1.0), load_dataset(root), load_gt_scene_meta(root), opt);
    EXPECT_FALSE(r.gt_mask);
    EXPECT_FALSE(r.has_albedo);
    EXPECT_FALSE(r.has_normal);
    EXPECT_FALSE(r.light_reference.has_value());  // it needs the true albedo and normals
    for (const GtEnvImageResult& im : r.images) {
        EXPECT_EQ(im.mask_pixels, std::size_t(64 * 48));  // test photos have no transients
        EXPECT_TRUE(std::isfinite(im.shadowed.psnr));
    }
    const nlohmann::ordered_json j = gt_env_metrics_json(r, {"run", root});
    EXPECT_FALSE(j.contains("albedo_scale"));
    EXPECT_FALSE(j["images"][0].contains("normal"));
    EXPECT_FALSE(j["light_scale"].contains("reference"));
    // A missing SH file of a test condition is named.
    const GtSceneMeta meta = load_gt_scene_meta(root);
    const std::string cond = meta.find(load_dataset(root).split(Split::Test)[0]->name)->condition;
    fs::remove(meta.sh_path(cond));
    try {
        evaluate_gt_env(oracle_run(tiny_scene(), 1.0), load_dataset(root), meta, opt);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_THAT(e.what(), HasSubstr(cond + "_sh.txt"));
    }
}

// ---- Missing files ------------------------------------------------------------------------------------

TEST(EvalGtEnv, MissingFilesAreNamed) {
    TempDir tmp("eval_missing");
    try {
        load_gt_scene_meta(tmp.str());
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_THAT(e.what(), HasSubstr((fs::path(tmp.str()) / "meta.json").string()));
    }
    try {
        load_relightable_run(tmp.str());
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_THAT(e.what(), HasSubstr((fs::path(tmp.str()) / "model.ply").string()));
    }
    {
        std::ofstream(tmp / "meta.json") << R"({"images": [{"name": "a.png"}]})";
        try {
            load_gt_scene_meta(tmp.str());
            FAIL() << "expected an error";
        } catch (const Error& e) {
            EXPECT_THAT(e.what(), HasSubstr("meta.json"));
            EXPECT_THAT(e.what(), HasSubstr("images[0]"));
        }
    }
}

}  // namespace
}  // namespace lumigauss
