// The training loop (train/trainer.h) on the tiny synthetic scene: a checkpoint of the default presets' state
// resumes bit-exactly, the checkpoint file round-trips and rejects damaged files, non-finite values stop a
// step before it changes the state, and the schedule (stages, frozen groups, camera order) is the official
// one. The longer trainings (three stages, learned environments, resume of the paper preset) are in
// tests/slow/train_end_to_end_test.cpp.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "lumigauss/io/dataset.h"
#include "lumigauss/model/ground_albedo.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/sh_text.h"
#include "lumigauss/shading/sky_colour.h"
#include "lumigauss/train/checkpoint.h"
#include "lumigauss/train/ground_light_prior.h"
#include "lumigauss/train/sky_hemisphere_prior.h"
#include "lumigauss/train/trainer.h"
#include "lumigauss/util/error.h"
#include "synth_test_util.h"
#include "trainer_test_util.h"

namespace lumigauss {
namespace {

using synth_test::TempDir;
using namespace trainer_test;
using ::testing::HasSubstr;

std::string read_file_bytes(const std::string& path) {
    return synth_test::read_bytes(path);
}

void write_file_bytes(const std::string& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
}

// The message of the lumigauss::Error that `f` throws ("" and a failure when it throws none or another).
template <class F>
std::string error_of(F&& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << "expected a lumigauss::Error, got: " << e.what();
        return {};
    }
    ADD_FAILURE() << "expected a lumigauss::Error, nothing was thrown";
    return {};
}

// The default presets' state (sky residuals with their per-photo optimizers, the sky losses, the prune after
// densification) resumes as exactly: the sky colour loss and the residual are switched on to exercise them.
TEST(TrainTrainer, ResumeIsBitExactWithTheSkyModel) {
    TrainConfig config = train_preset("fast");
    config.sky_residual = true;
    config.lambda_sky_colour = 0.5;
    config.lighting_init_radiance = 0.5;
    config.iterations = 100;
    config.warmup = 65, config.start_shadowed = 75;
    config.densify_from = 10, config.densify_until = 50, config.densify_interval = 20;
    config.opacity_reset_interval = 40, config.start_regularization = 30, config.background_alpha_from = 10;
    Trainer straight = make_trainer(config);
    while (!straight.done()) straight.step();

    TempDir tmp("train_resume_sky");
    const std::string path = tmp / "half.lgck";
    {
        Trainer first = make_trainer(config);
        while (first.iteration() < 55) first.step();
        save_checkpoint(path, first.state());
    }
    Trainer resumed(tiny_scene().views, load_checkpoint(path));
    int pruned_alone = 0;
    while (!resumed.done()) pruned_alone += resumed.step().prune_ran ? 1 : 0;
    // At 60 and 80: every densify_interval from densify_until on, outside stage 2, not the last iteration.
    EXPECT_EQ(pruned_alone, 2);
    expect_same_state(straight.state(), resumed.state());
    double moved = 0;
    for (float v : resumed.state().sky_residuals.params()) moved += std::abs(v);
    EXPECT_GT(moved, 0.0) << "the sky residuals were never trained";
}

// The ground-light prior reaches the lights: trained with it, their lower halves lie nearer the ground's
// reflection than without it, and the steps report it only when it is on.
TEST(TrainTrainer, GroundLightPriorPullsTheLowerHalfTowardsTheGround) {
    const auto lower_half_error = [](double weight, bool& reported) {
        TrainConfig config = train_preset("fast");
        config.lambda_ground_light = weight;
        config.ground_light_albedo = 0.2;
        config.iterations = 120;
        config.warmup = 110, config.start_shadowed = 115;
        config.densify_from = 1000;
        Trainer trainer = make_trainer(config);
        reported = false;
        while (!trainer.done()) {
            const StepReport report = trainer.step();  // stepped every time, whatever was reported
            reported = reported || report.ground_light > 0;
        }
        const Vec3f up{0, 0, 1};
        const Vec3d reflectance = ground_reflectance(ground_albedo(trainer.state().model, up), 0.2);
        double sum = 0;
        for (int v = 0; v < int(trainer.views().size()); ++v) {
            ShCoeffs<float> unused{};
            sum += ground_light_prior(trainer.environment(v), up, reflectance, 0.0, unused);
        }
        return sum / double(trainer.views().size());
    };
    bool reported_off = true, reported_on = false;
    const double off = lower_half_error(0.0, reported_off);
    const double on = lower_half_error(10.0, reported_on);
    EXPECT_FALSE(reported_off);
    EXPECT_TRUE(reported_on);
    EXPECT_LT(on, 0.5 * off) << "without " << off << ", with " << on;
}

// The sky hemisphere prior reaches the photos' sky residuals: trained with it, each photo's sky over the
// upper hemisphere (light + residual; mostly outside the photo's view, where the prior acts) lies nearer the
// mean of its sky pixels than without, and the steps report the prior only when it is on.
TEST(TrainTrainer, SkyHemispherePriorPullsEachPhotosSkyTowardsItsSkyPixels) {
    const auto hemisphere_error = [](double weight, bool& reported) {
        TrainConfig config = train_preset("fast");
        config.lambda_sky_hemisphere = weight;
        config.lr_sky_residual = 0.1;  // a few steps per photo: let each move the residual far enough
        config.iterations = 120;
        config.warmup = 110, config.start_shadowed = 115;
        config.densify_from = 1000;
        Trainer trainer = make_trainer(config);
        reported = false;
        while (!trainer.done()) reported = trainer.step().sky_hemisphere > 0 || reported;
        const Vec3f up{0, 0, 1};
        const std::vector<Vec3f> probe = upper_hemisphere_directions(up, 301);
        double sum = 0;
        int photos = 0;
        for (int v = 0; v < int(trainer.views().size()); ++v) {
            const TrainView& view = trainer.views()[std::size_t(v)];
            const std::optional<Vec3f> target = mean_sky_radiance(view.rgb.pixels, view.sky.pixels, 1);
            if (!target) continue;
            const Sh4Coeffs<float> residual = trainer.state().sky_residuals.get(v);
            for (const Vec3f& d : probe)
                sum += double(length(sky_radiance(trainer.environment(v), &residual, d) - *target));
            photos += 1;
        }
        EXPECT_GT(photos, 0) << "the tiny scene has sky masks";
        return sum / double(std::max(photos, 1) * int(probe.size()));
    };
    bool reported_off = true, reported_on = false;
    const double off = hemisphere_error(0.0, reported_off);
    const double on = hemisphere_error(1.0, reported_on);
    EXPECT_FALSE(reported_off);
    EXPECT_TRUE(reported_on);
    EXPECT_LT(on, 0.5 * off) << "without " << off << ", with " << on;
}

// The side rule training shades with (shading/surfel_side.h): the config's angle about the photos' up, as
// load_trained_run rebuilds it for every later render of the run.
TEST(TrainTrainer, SideRuleIsTheConfigAngleAboutThePhotosUp) {
    TrainConfig config = train_preset("fast");
    config.iterations = 10;
    EXPECT_EQ(make_trainer(config).side_rule().grazing_degrees, 5.0f);
    config.grazing_side_degrees = 0;
    const Trainer trainer = make_trainer(config);
    EXPECT_FALSE(trainer.side_rule().active());
    for (int k = 0; k < 3; ++k)
        EXPECT_EQ(trainer.side_rule().up[k], trainer.sky_horizon().up[k]);  // the photos' up, as the sky's
}

TEST(TrainTrainer, ConstructorsRejectInconsistentInput) {
    TrainConfig config = train_preset("paper-fast");
    config.iterations = 10;
    const TinyScene& s = tiny_scene();
    const Trainer trainer = make_trainer(config);
    // A saved state continues only on the photos it was trained on, in the same order.
    TrainState swapped = trainer.state();
    std::swap(swapped.image_names[0], swapped.image_names[1]);
    EXPECT_THAT(error_of([&] { Trainer t(s.views, swapped); }), HasSubstr(s.views[0].name));
    std::vector<TrainView> fewer(s.views.begin(), s.views.end() - 1);
    EXPECT_THAT(error_of([&] { Trainer t(fewer, trainer.state()); }), HasSubstr("photos"));
    // A new run needs SfM points and photos, and a valid config.
    EXPECT_THAT(error_of([&] { Trainer t(s.views, {}, {}, config); }), HasSubstr("SfM"));
    EXPECT_THAT(error_of([&] { Trainer t({}, s.data.point_xyz, s.data.point_rgb, config); }),
                HasSubstr("photo"));
    TrainConfig bad = config;
    bad.warmup = bad.start_shadowed + 1;
    EXPECT_THAT(error_of([&] { Trainer t(s.views, s.data.point_xyz, s.data.point_rgb, bad); }),
                HasSubstr("warmup"));
}

// ---- 4. Checkpoint files ----------------------------------------------------------------------------------

TEST(TrainTrainer, CheckpointRoundTripsEveryField) {
    TrainConfig config = train_preset("paper-fast");
    config.iterations = 40;
    config.warmup = 25;
    config.start_shadowed = 30;
    config.densify_from = 5;
    config.densify_interval = 10;
    config.seed = 7;
    config.lambda_shadow = 3.25;
    Trainer trainer = make_trainer(config);
    while (trainer.iteration() < 35) trainer.step();  // stage 3, after densification
    const TrainState& state = trainer.state();
    ASSERT_GT(state.model.adam(ModelParam::Xyz).step_count(), 0);
    ASSERT_FALSE(state.model.grad_accum().empty());

    TempDir tmp("train_ckpt");
    const std::string path = tmp / "run.lgck";
    save_checkpoint(path, state);
    const TrainState loaded = load_checkpoint(path);
    expect_same_state(state, loaded);
    EXPECT_EQ(loaded.config.seed, 7u);
    EXPECT_EQ(loaded.config.lambda_shadow, 3.25);
    EXPECT_EQ(loaded.iteration, 35);
    // Saving the loaded state gives the same bytes.
    const std::string again = tmp / "again.lgck";
    save_checkpoint(again, loaded);
    EXPECT_EQ(read_file_bytes(path), read_file_bytes(again));
}

TEST(TrainTrainer, DamagedCheckpointsThrowErrorsNamingTheFile) {
    TrainConfig config = train_preset("paper-fast");
    config.iterations = 10;
    Trainer trainer = make_trainer(config);
    while (!trainer.done()) trainer.step();
    TempDir tmp("train_ckpt_bad");
    const std::string good = tmp / "good.lgck";
    save_checkpoint(good, trainer.state());
    const std::string bytes = read_file_bytes(good);
    ASSERT_GT(bytes.size(), 1000u);

    const std::size_t n = bytes.size();
    for (const std::size_t cut : {std::size_t(0), std::size_t(3), std::size_t(8), std::size_t(12),
                                  std::size_t(100), n / 3, n / 2, n - 9, n - 8, n - 1}) {
        const std::string path = tmp / ("cut_" + std::to_string(cut) + ".lgck");
        write_file_bytes(path, bytes.substr(0, cut));
        const std::string message = error_of([&] { load_checkpoint(path); });
        EXPECT_THAT(message, HasSubstr(path)) << "cut at " << cut << " of " << n;
    }
    {
        const std::string path = tmp / "magic.lgck";
        write_file_bytes(path, "NOTACKPT" + bytes.substr(8));
        const std::string message = error_of([&] { load_checkpoint(path); });
        EXPECT_THAT(message, HasSubstr(path));
        EXPECT_THAT(message, HasSubstr("magic"));
    }
    {
        const std::string path = tmp / "end.lgck";
        write_file_bytes(path, bytes.substr(0, n - 8) + "XXXXXXXX");
        EXPECT_THAT(error_of([&] { load_checkpoint(path); }), HasSubstr(path));
    }
    {
        const std::string path = tmp / "missing.lgck";
        EXPECT_THAT(error_of([&] { load_checkpoint(path); }), HasSubstr(path));
    }
}

// ---- 5. Non-finite values stop the step before it changes the state ----------------------------------

// The NonFiniteError the next step throws (none: a failure), after checking that nothing in the state moved.
std::optional<NonFiniteError> non_finite_step(Trainer& trainer) {
    const TrainState before = trainer.state();
    const std::int64_t it = trainer.iteration();
    try {
        trainer.step();
    } catch (const NonFiniteError& e) {
        EXPECT_EQ(trainer.iteration(), it);
        expect_same_state(before, trainer.state());
        return e;
    }
    ADD_FAILURE() << "step " << it + 1 << " threw no NonFiniteError";
    return std::nullopt;
}

// Regression test of a fixed bug: a NaN raw albedo went undetected while albedo_activation
// (shading/surfel_shading.h) mapped NaN to 0 with a 0 gradient, so the NaN stayed in the model (a probe
// trained 195 more iterations with it). The activation now lets NaN through, as torch's clamp does, and the
// loss reports it.
TEST(TrainTrainer, NanAlbedoThrowsNonFiniteErrorWithoutAdvancing) {
    TrainConfig config = train_preset("paper-fast");
    config.iterations = 20;
    Trainer trainer = make_trainer(config);
    for (int i = 0; i < 5; ++i) trainer.step();
    // A surfel in plain view of the next photo: the nearest one whose centre projects well inside it.
    const Camera& camera = trainer.views()[std::size_t(trainer.view_for_iteration(6))].camera;
    const auto& xyz = trainer.state().model.param(ModelParam::Xyz);
    std::size_t chosen = xyz.size();
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < trainer.state().model.size(); ++i) {
        const Vec3d p = camera.world_to_camera({xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]});
        if (p.z <= 0.1) continue;
        const double u = camera.fx * p.x / p.z + camera.cx, v = camera.fy * p.y / p.z + camera.cy;
        if (u < 4 || v < 4 || u > camera.width - 4 || v > camera.height - 4) continue;
        if (p.z < nearest) nearest = p.z, chosen = i;
    }
    ASSERT_LT(chosen, xyz.size());
    trainer.state().model.param(ModelParam::Albedo)[3 * chosen + 1] = std::numeric_limits<float>::quiet_NaN();

    const std::optional<NonFiniteError> e = non_finite_step(trainer);
    ASSERT_TRUE(e.has_value());
    EXPECT_EQ(e->iteration, 6);
    EXPECT_FALSE(e->term.empty());
    EXPECT_THAT(e->what(), HasSubstr("iteration 6"));
    EXPECT_THAT(e->what(), HasSubstr(e->term));
}

// Regression test of a fixed bug: a NaN environment coefficient went undetected while light_intensity
// (surfel_shading.h) turned a NaN irradiance into its 1e-5 floor with a 0 gradient and l_+ skipped NaN
// radiance. NaN now passes through light_intensity, so the loss reports it.
TEST(TrainTrainer, NanLightingThrowsNonFiniteErrorWithoutAdvancing) {
    TrainConfig config = train_preset("paper-fast");
    config.iterations = 20;
    Trainer trainer = make_trainer(config);
    for (int i = 0; i < 5; ++i) trainer.step();
    // The bias of output 0 of the lighting MLP: the red DC coefficient of every photo's environment.
    trainer.state().lighting.param(MlpGroup::kB3)[0] = std::numeric_limits<float>::quiet_NaN();
    ASSERT_TRUE(std::isnan(trainer.state().lighting.env_sh(0).c[0].x));

    const std::optional<NonFiniteError> e = non_finite_step(trainer);
    ASSERT_TRUE(e.has_value());
    EXPECT_EQ(e->iteration, 6);
    EXPECT_THAT(e->what(), HasSubstr("iteration 6"));
    EXPECT_THAT(e->what(), HasSubstr(e->term));
}

TEST(TrainTrainer, NanTransferThrowsNonFiniteErrorInStageTwo) {
    TrainConfig config = train_preset("paper-fast");
    config.iterations = 20;
    config.warmup = 4;
    config.start_shadowed = 8;
    Trainer trainer = make_trainer(config);
    for (int i = 0; i < 4; ++i) trainer.step();  // iterations 1..4; 5 is in stage 2
    ASSERT_EQ(stage_of(config, 5), Stage::TransferFitting);
    // Channel 0 of coefficient 2 of surfel 3, in the transfer set the next photo uses.
    ViewNormals normals;
    compute_view_normals(trainer.state().model,
                         trainer.views()[std::size_t(trainer.view_for_iteration(5))].camera, normals);
    const ModelParam side =
        normals.positive_side[3] ? ModelParam::TransferPositive : ModelParam::TransferNegative;
    trainer.state().model.param(side)[3 * kTransferStored + 2 * 3] = std::numeric_limits<float>::quiet_NaN();

    const std::optional<NonFiniteError> e = non_finite_step(trainer);
    ASSERT_TRUE(e.has_value());
    EXPECT_EQ(e->iteration, 5);
    EXPECT_THAT(e->what(), HasSubstr("iteration 5"));
    EXPECT_THAT(e->term, HasSubstr("l_"));  // one of the transfer losses
    EXPECT_THAT(e->what(), HasSubstr(e->term));
}

// ---- 6. Schedule details
// -----------------------------------------------------------------------------------

TEST(TrainTrainer, StageOfFollowsTheOfficialBoundaries) {
    const TrainConfig paper = train_preset("paper");
    EXPECT_EQ(stage_of(paper, 1), Stage::Unshadowed);
    EXPECT_EQ(stage_of(paper, 19999), Stage::Unshadowed);
    EXPECT_EQ(stage_of(paper, 20000), Stage::TransferFitting);
    EXPECT_EQ(stage_of(paper, 20500), Stage::TransferFitting);
    EXPECT_EQ(stage_of(paper, 20501), Stage::Shadowed);
    EXPECT_EQ(stage_of(paper, 40000), Stage::Shadowed);
    TrainConfig c = paper;
    c.warmup = 10;
    c.start_shadowed = 10;  // a one-iteration stage 2
    EXPECT_EQ(stage_of(c, 9), Stage::Unshadowed);
    EXPECT_EQ(stage_of(c, 10), Stage::TransferFitting);
    EXPECT_EQ(stage_of(c, 11), Stage::Shadowed);
    EXPECT_STREQ(stage_name(Stage::Unshadowed), "unshadowed");
    EXPECT_STREQ(stage_name(Stage::TransferFitting), "transfer");
    EXPECT_STREQ(stage_name(Stage::Shadowed), "shadowed");
}

TEST(TrainTrainer, StageOneFreezesTransferAndStageTwoUpdatesOnlyTransfer) {
    TrainConfig config = train_preset("paper-fast");
    config.iterations = 60;
    config.warmup = 20;
    config.start_shadowed = 30;
    config.densify_from = 5;
    config.densify_interval = 5;
    config.opacity_reset_interval = 15;
    Trainer trainer = make_trainer(config);
    const auto& model = trainer.state().model;

    // Stage 1 (1..19): the transfer stays exactly 0.01 everywhere, through densification and a reset.
    int densified = 0;
    while (trainer.iteration() < 19) {
        const StepReport r = trainer.step();
        ASSERT_EQ(r.stage, Stage::Unshadowed);
        densified += r.densify_ran ? 1 : 0;
        EXPECT_EQ(r.consistency, 0.0);
        EXPECT_EQ(r.range01, 0.0);
        for (const ModelParam side : {ModelParam::TransferPositive, ModelParam::TransferNegative}) {
            ASSERT_EQ(model.param(side).size(), model.size() * std::size_t(kTransferStored));
            for (const float v : model.param(side)) ASSERT_EQ(v, 0.01f) << "iteration " << r.iteration;
        }
    }
    EXPECT_GE(densified, 2);

    // Stage 2 (20..30): no render, only the transfer moves; the lighting and rotation rates are 0 after 20.
    const std::size_t surfels = model.size();
    while (trainer.iteration() < 30) {
        const TrainState before = trainer.state();
        const StepReport r = trainer.step();
        SCOPED_TRACE("iteration " + std::to_string(r.iteration));
        ASSERT_EQ(r.stage, Stage::TransferFitting);
        EXPECT_EQ(r.psnr, 0.0);
        EXPECT_EQ(r.l1_shadowed, 0.0);
        EXPECT_EQ(r.dssim_shadowed, 0.0);
        EXPECT_EQ(r.l1_unshadowed, 0.0);
        EXPECT_EQ(r.dssim_unshadowed, 0.0);
        EXPECT_EQ(r.env, 0.0);
        EXPECT_EQ(r.normal, 0.0);
        EXPECT_EQ(r.distortion, 0.0);
        // l_shadow may be reported (it is computed with the others) but has weight 0 in stage 2.
        EXPECT_GT(r.consistency, 0.0);
        EXPECT_NEAR(r.total, config.lambda_consistency * r.consistency + config.lambda_range01 * r.range01,
                    1e-9 * r.total);
        EXPECT_FALSE(r.densify_ran);
        EXPECT_EQ(r.surfels, surfels);
        for (const ModelParam p : {ModelParam::Xyz, ModelParam::Rotation, ModelParam::Scaling,
                                   ModelParam::Opacity, ModelParam::Albedo}) {
            EXPECT_TRUE(same_bits(before.model.param(p), model.param(p))) << GaussianModel::name(p);
            EXPECT_TRUE(same_bits(before.model.adam(p).exp_avg(), model.adam(p).exp_avg()))
                << GaussianModel::name(p);
        }
        for (int g = 0; g < kMlpGroupCount; ++g)
            EXPECT_TRUE(
                same_bits(before.lighting.param(MlpGroup(g)), trainer.state().lighting.param(MlpGroup(g))))
                << mlp_group_name(MlpGroup(g));
        EXPECT_FALSE(same_bits(before.model.param(ModelParam::TransferPositive),
                               model.param(ModelParam::TransferPositive)) &&
                     same_bits(before.model.param(ModelParam::TransferNegative),
                               model.param(ModelParam::TransferNegative)))
            << "the transfer did not move";
        if (r.iteration > config.warmup) {
            EXPECT_EQ(model.adam(ModelParam::Rotation).lr(), 0.0);
            for (const AdamGroup& g : trainer.state().lighting_adam) EXPECT_EQ(g.lr(), 0.0) << g.name();
        }
    }

    // Stage 3: the rotation rate is back, the lighting rates are divided by lr_env_final_ratio.
    const StepReport r = trainer.step();
    EXPECT_EQ(r.stage, Stage::Shadowed);
    EXPECT_EQ(model.adam(ModelParam::Rotation).lr(), config.lr_rotation);
    EXPECT_DOUBLE_EQ(trainer.state().lighting_adam[0].lr(), config.lr_embedding / config.lr_env_final_ratio);
    EXPECT_DOUBLE_EQ(trainer.state().lighting_adam[1].lr(), config.lr_mlp / config.lr_env_final_ratio);
}

TEST(TrainTrainer, ViewOrderVisitsEveryPhotoOncePerEpoch) {
    TrainConfig config = train_preset("paper-fast");
    config.iterations = 24;
    Trainer trainer = make_trainer(config);
    const int n = int(trainer.views().size());
    ASSERT_EQ(n, 8);
    std::vector<std::vector<int>> epochs;
    for (int e = 0; e < 6; ++e) {
        std::vector<int> order;
        for (int k = 1; k <= n; ++k) order.push_back(trainer.view_for_iteration(std::int64_t(e) * n + k));
        std::vector<int> sorted = order;
        std::sort(sorted.begin(), sorted.end());
        std::vector<int> all(static_cast<std::size_t>(n));
        std::iota(all.begin(), all.end(), 0);
        EXPECT_EQ(sorted, all) << "epoch " << e;
        if (!epochs.empty()) {
            EXPECT_NE(order, epochs.back()) << "epoch " << e << " repeats the previous one";
        }
        epochs.push_back(order);
    }
    // step() renders the view view_for_iteration names.
    while (!trainer.done()) {
        const std::int64_t it = trainer.iteration() + 1;
        EXPECT_EQ(trainer.step().view, trainer.view_for_iteration(it)) << it;
    }
    // Another seed, another order.
    config.seed = 1;
    const Trainer other = make_trainer(config);
    std::vector<int> first;
    for (int k = 1; k <= n; ++k) first.push_back(other.view_for_iteration(k));
    EXPECT_NE(first, epochs[0]);
}

}  // namespace
}  // namespace lumigauss
