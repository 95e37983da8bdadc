// The training loop (train/trainer.h) on the tiny synthetic scene: the three stages lower the loss and raise
// the PSNR, the learned per-photo environments follow the true ones, a checkpoint resumes bit-exactly, the
// checkpoint file round-trips and rejects damaged files, non-finite values stop a step before it changes the
// state, and the schedule (stages, frozen groups, camera order) is the official one.
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
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/sh_text.h"
#include "lumigauss/train/checkpoint.h"
#include "lumigauss/train/trainer.h"
#include "lumigauss/util/error.h"
#include "support/sanitizers.h"
#include "synth_test_util.h"

namespace lumigauss {
namespace {

using synth_test::TempDir;
using ::testing::HasSubstr;

// ---- The tiny scene, generated once per test process ---------------------------------------------------

struct TinyScene {
    std::string root;
    Dataset data;
    std::vector<TrainView> views;
};

const TinyScene& tiny_scene() {
    static TempDir dir("train_trainer");
    static const TinyScene scene = [] {
        synth::generate_synthetic_scene(synth_test::tiny_options(dir.str()));
        TinyScene s;
        s.root = dir.str();
        s.data = load_dataset(s.root, DatasetOptions{});
        s.views = load_train_views(s.data);
        return s;
    }();
    return scene;
}

Trainer make_trainer(const TrainConfig& config) {
    const TinyScene& s = tiny_scene();
    return Trainer(s.views, s.data.point_xyz, s.data.point_rgb, config);
}

// The fast preset with its schedule shrunk so that all three stages and some densification fit in a few
// hundred iterations.
TrainConfig shrunk_config() {
    TrainConfig c = train_preset("paper-fast");
    c.iterations = 400;
    c.warmup = 200;
    c.start_shadowed = 220;
    c.densify_from = 50;
    c.densify_until = 180;
    c.densify_interval = 50;
    c.opacity_reset_interval = 150;
    c.start_regularization = 100;
    c.lr_position_max_steps = 300;
    return c;
}

// ---- Bitwise comparison of states ----------------------------------------------------------------------

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

void expect_same_adam(const AdamGroup& a, const AdamGroup& b, const std::string& what) {
    EXPECT_EQ(a.step_count(), b.step_count()) << what;
    EXPECT_TRUE(same_bits(a.exp_avg(), b.exp_avg())) << what << " exp_avg";
    EXPECT_TRUE(same_bits(a.exp_avg_sq(), b.exp_avg_sq())) << what << " exp_avg_sq";
    EXPECT_EQ(a.row_width(), b.row_width()) << what;
}

// Everything a TrainState holds, bit for bit (learning rates are not state: step() sets them first).
void expect_same_state(const TrainState& a, const TrainState& b) {
    EXPECT_EQ(train_config_to_json(a.config), train_config_to_json(b.config));
    EXPECT_EQ(a.iteration, b.iteration);
    EXPECT_EQ(a.scene_extent, b.scene_extent);
    EXPECT_EQ(a.image_names, b.image_names);
    ASSERT_EQ(a.model.size(), b.model.size());
    for (int p = 0; p < kModelParamCount; ++p) {
        const auto param = ModelParam(p);
        const std::string name = GaussianModel::name(param);
        EXPECT_TRUE(same_bits(a.model.param(param), b.model.param(param))) << name;
        expect_same_adam(a.model.adam(param), b.model.adam(param), name);
    }
    EXPECT_TRUE(same_bits(a.model.grad_accum(), b.model.grad_accum())) << "grad_accum";
    EXPECT_TRUE(same_bits(a.model.grad_count(), b.model.grad_count())) << "grad_count";
    EXPECT_TRUE(same_bits(a.model.max_radii(), b.model.max_radii())) << "max_radii";
    EXPECT_EQ(a.model.spatial_lr_scale(), b.model.spatial_lr_scale());
    ASSERT_EQ(a.lighting.num_images(), b.lighting.num_images());
    ASSERT_EQ(a.lighting_adam.size(), b.lighting_adam.size());
    for (int g = 0; g < kMlpGroupCount; ++g) {
        const std::string name = std::string("lighting ") + mlp_group_name(MlpGroup(g));
        EXPECT_TRUE(same_bits(a.lighting.param(MlpGroup(g)), b.lighting.param(MlpGroup(g)))) << name;
        expect_same_adam(a.lighting_adam[std::size_t(g)], b.lighting_adam[std::size_t(g)], name);
    }
    EXPECT_TRUE(same_bits(a.sky_residuals.params(), b.sky_residuals.params())) << "sky residuals";
    ASSERT_EQ(a.sky_residual_adam.size(), b.sky_residual_adam.size());
    for (std::size_t i = 0; i < a.sky_residual_adam.size(); ++i)
        expect_same_adam(a.sky_residual_adam[i], b.sky_residual_adam[i], "sky residual " + std::to_string(i));
}

double mean_of(const std::vector<StepReport>& reports, std::size_t first, std::size_t count,
               double StepReport::*field) {
    double sum = 0;
    for (std::size_t i = first; i < first + count; ++i) sum += reports[i].*field;
    return sum / double(count);
}

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

// ---- 1. Training lowers the loss and raises the PSNR, through all three stages -------------------------

TEST(TrainTrainer, ThreeStagesLowerTheLossAndRaiseThePsnr) {
    const TrainConfig config = shrunk_config();
    Trainer trainer = make_trainer(config);
    const std::size_t initial_surfels = trainer.state().model.size();
    ASSERT_EQ(initial_surfels, tiny_scene().data.point_xyz.size());
    std::vector<StepReport> reports;
    while (!trainer.done()) reports.push_back(trainer.step());
    ASSERT_EQ(reports.size(), 400u);
    EXPECT_EQ(trainer.iteration(), 400);

    // Stage transitions at the configured iterations: 1..199 stage 1, 200..220 stage 2, 221..400 stage 3.
    for (const StepReport& r : reports) {
        const Stage expected = r.iteration < 200    ? Stage::Unshadowed
                               : r.iteration <= 220 ? Stage::TransferFitting
                                                    : Stage::Shadowed;
        ASSERT_EQ(r.stage, expected) << "iteration " << r.iteration;
    }
    for (std::size_t i = 0; i < reports.size(); ++i) ASSERT_EQ(reports[i].iteration, std::int64_t(i) + 1);

    // Densification at 100 and 150 only (it > densify_from, it % 50 == 0, it < densify_until = 180), an
    // opacity reset at 150; the surfel count changes at those iterations and nowhere else.
    std::set<std::int64_t> densified, reset;
    std::size_t previous = initial_surfels;
    for (const StepReport& r : reports) {
        if (r.densify_ran) densified.insert(r.iteration);
        if (r.opacity_reset) reset.insert(r.iteration);
        if (!r.densify_ran) {
            EXPECT_EQ(r.surfels, previous) << "iteration " << r.iteration;
        }
        previous = r.surfels;
    }
    EXPECT_EQ(densified, (std::set<std::int64_t>{100, 150}));
    EXPECT_EQ(reset, (std::set<std::int64_t>{150}));
    EXPECT_NE(reports[99].surfels, initial_surfels) << "densification at 100 did not change the model";
    EXPECT_EQ(trainer.state().model.size(), reports.back().surfels);

    // Per stage: the mean of the first 20 vs the last 20 iterations (stage 2: its 21 iterations, 5 vs 5).
    const auto s1_first_loss = mean_of(reports, 0, 20, &StepReport::total);
    const auto s1_last_loss = mean_of(reports, 179, 20, &StepReport::total);
    const auto s1_first_psnr = mean_of(reports, 0, 20, &StepReport::psnr);
    const auto s1_last_psnr = mean_of(reports, 179, 20, &StepReport::psnr);
    const auto s2_first_loss = mean_of(reports, 199, 5, &StepReport::total);
    const auto s2_last_loss = mean_of(reports, 215, 5, &StepReport::total);
    const auto s3_first_loss = mean_of(reports, 220, 20, &StepReport::total);
    const auto s3_last_loss = mean_of(reports, 380, 20, &StepReport::total);
    const auto s3_first_psnr = mean_of(reports, 220, 20, &StepReport::psnr);
    const auto s3_last_psnr = mean_of(reports, 380, 20, &StepReport::psnr);
    std::printf(
        "[ measured ] stage 1 loss %.4f -> %.4f, psnr %.2f -> %.2f; stage 2 loss %.4f -> %.4f; stage 3 loss "
        "%.4f -> %.4f, psnr %.2f -> %.2f; surfels %zu -> %zu\n",
        s1_first_loss, s1_last_loss, s1_first_psnr, s1_last_psnr, s2_first_loss, s2_last_loss, s3_first_loss,
        s3_last_loss, s3_first_psnr, s3_last_psnr, initial_surfels, reports.back().surfels);
    EXPECT_LT(s1_last_loss, s1_first_loss);
    EXPECT_GT(s1_last_psnr, s1_first_psnr);
    EXPECT_LT(s2_last_loss, s2_first_loss);
    EXPECT_LT(s3_last_loss, s3_first_loss);
    EXPECT_GT(s3_last_psnr, s3_first_psnr);
    // Measured 22.94 dB (shadowed, mean of the last 20 iterations; the first 20 of stage 3: 9.05 dB).
    EXPECT_GT(s3_last_psnr, 19.0);

    // What each stage computes: stage 1 no transfer losses, stage 2 no image, stage 3 everything.
    for (const StepReport& r : reports) {
        SCOPED_TRACE("iteration " + std::to_string(r.iteration));
        ASSERT_TRUE(std::isfinite(r.total));
        if (r.stage == Stage::Unshadowed) {
            EXPECT_GT(r.psnr, 0.0);
            EXPECT_GT(r.l1_unshadowed, 0.0);
            EXPECT_EQ(r.l1_shadowed, 0.0);
            EXPECT_EQ(r.consistency, 0.0);
            EXPECT_EQ(r.shadow, 0.0);
            EXPECT_EQ(r.normal != 0.0, r.iteration > config.start_regularization);
        } else if (r.stage == Stage::Shadowed) {
            EXPECT_GT(r.psnr, 0.0);
            EXPECT_GT(r.l1_shadowed, 0.0);
            EXPECT_GT(r.l1_unshadowed, 0.0);
            EXPECT_GT(r.consistency, 0.0);
            EXPECT_NE(r.normal, 0.0);
        }
    }
}

// ---- 2. The learned per-photo environments follow the true ones ------------------------------------------

double pearson(const std::vector<double>& a, const std::vector<double>& b) {
    const double n = double(a.size());
    const double ma = std::accumulate(a.begin(), a.end(), 0.0) / n;
    const double mb = std::accumulate(b.begin(), b.end(), 0.0) / n;
    double sab = 0, saa = 0, sbb = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        sab += (a[i] - ma) * (b[i] - mb);
        saa += (a[i] - ma) * (a[i] - ma);
        sbb += (b[i] - mb) * (b[i] - mb);
    }
    return sab / std::sqrt(saa * sbb);
}

// The photos are sRGB(exposure * radiance) and the model renders albedo * E^(1/2.2), so the learned
// irradiance of photo i should be proportional to exposure_i * E_true_i; albedo absorbs the global scale,
// hence the scale-free comparison (Pearson correlation).
//
// Measured (seed 0, 600 stage-1 iterations), Pearson r between learned and true:
//   per-photo mean irradiance over the 19 normals (8 values):  0.856  (300 it: 0.876, 1200 it: 0.809;
//                                                               untrained: -0.373, 50 it: 0.570)
//   irradiance of an up-facing surface, per photo (8 values):   0.907  (untrained: -0.349)
//   all (photo, normal) pairs pooled (152 values):              0.369  (untrained: 0.336 -- not asserted:
//     the pooled value is dominated by the up/side contrast of the normals, which even an untrained model
//     shares by chance; the tiny scene's few surface orientations do not pin down the directional detail)
TEST(TrainTrainer, LearnedEnvironmentsCorrelateWithTheTrueOnes) {
    LUMIGAUSS_OUTCOME_ONLY_IN_RELEASE();  // stage 1 under the sanitizers: ThreeStagesLowerTheLoss...
    TrainConfig config = train_preset("paper-fast");
    config.iterations = 600;  // stage 1 only
    config.warmup = 1000;
    config.start_shadowed = 1000;
    Trainer trainer = make_trainer(config);
    while (!trainer.done()) trainer.step();

    const TinyScene& s = tiny_scene();
    const auto meta = synth_test::read_json(s.root + "/meta.json");
    // 19 normals on the upper hemisphere (+Z up): the zenith and rings of 6 at 30, 55 and 80 degrees.
    std::vector<Vec3d> normals{{0, 0, 1}};
    for (const double polar_deg : {30.0, 55.0, 80.0})
        for (int k = 0; k < 6; ++k) {
            const double t = polar_deg * std::numbers::pi / 180;
            const double p = (2 * std::numbers::pi * k) / 6 + polar_deg * std::numbers::pi / 360;
            normals.push_back({std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)});
        }
    const auto gray = [](Vec3d e) { return (e.x + e.y + e.z) / 3; };
    std::vector<double> learned, truth, learned_mean, truth_mean, learned_up, truth_up;
    const auto& names = trainer.state().image_names;
    ASSERT_EQ(names.size(), 8u);
    for (std::size_t i = 0; i < names.size(); ++i) {
        const nlohmann::json* image = nullptr;
        for (const auto& im : meta["images"])
            if (im["name"].get<std::string>() == names[i]) image = &im;
        ASSERT_NE(image, nullptr) << names[i];
        const double exposure = (*image)["exposure"].get<double>();
        const ShCoeffs<double> true_sh =
            read_sh_text(s.root + "/env/" + (*image)["condition"].get<std::string>() + "_sh.txt");
        const ShCoeffs<double> learned_sh = trainer.state().lighting.env_sh(int(i)).cast<double>();
        double lm = 0, tm = 0;
        for (const Vec3d& n : normals) {
            learned.push_back(gray(irradiance(learned_sh, n)));
            truth.push_back(exposure * gray(irradiance(true_sh, n)));
            lm += learned.back() / double(normals.size());
            tm += truth.back() / double(normals.size());
        }
        learned_mean.push_back(lm);
        truth_mean.push_back(tm);
        learned_up.push_back(gray(irradiance(learned_sh, Vec3d{0, 0, 1})));
        truth_up.push_back(exposure * gray(irradiance(true_sh, Vec3d{0, 0, 1})));
    }
    const double r_pairs = pearson(learned, truth);
    const double r_means = pearson(learned_mean, truth_mean);
    const double r_up = pearson(learned_up, truth_up);
    std::printf(
        "[ measured ] env correlation: per-photo means r = %.3f, up-facing r = %.3f, %zu pairs r = %.3f\n",
        r_means, r_up, learned.size(), r_pairs);
    EXPECT_GT(r_means, 0.7);  // measured 0.856
    EXPECT_GT(r_up, 0.75);    // measured 0.907
}

// ---- 3. Resume is exact -----------------------------------------------------------------------------------

TEST(TrainTrainer, ResumeFromACheckpointIsBitExact) {
    TrainConfig config = train_preset("paper-fast");
    // Second half (61..120): densification at 75 and 100, an opacity reset at 100 (after that densification),
    // stage 2 from 80, stage 3 from 91, regularisation from 66; the last iteration (120) takes no optimizer
    // step. (A reset shortly before a densification would prune every surfel: opacity 0.01 < min_opacity.)
    config.iterations = 120;
    config.warmup = 80;
    config.start_shadowed = 90;
    config.densify_from = 20;
    config.densify_until = 110;
    config.densify_interval = 25;
    config.opacity_reset_interval = 100;
    config.start_regularization = 65;
    config.lr_position_max_steps = 100;

    Trainer straight = make_trainer(config);
    std::vector<StepReport> straight_reports;
    while (!straight.done()) straight_reports.push_back(straight.step());

    TempDir tmp("train_resume");
    const std::string path = tmp / "half.lgck";
    {
        Trainer first = make_trainer(config);
        while (first.iteration() < 60) first.step();
        save_checkpoint(path, first.state());
    }
    Trainer resumed(tiny_scene().views, load_checkpoint(path));
    EXPECT_EQ(resumed.iteration(), 60);
    std::vector<StepReport> resumed_reports;
    while (!resumed.done()) resumed_reports.push_back(resumed.step());
    ASSERT_EQ(resumed_reports.size(), 60u);

    // The second half really exercised densification and both transitions.
    // Measured: at 75 48 cloned, 641 split, 124 pruned; at 100 110 cloned, 648 split, 22 pruned (2081 left).
    int densified = 0;
    std::size_t added = 0;
    std::set<Stage> stages;
    for (const StepReport& r : resumed_reports) {
        densified += r.densify_ran ? 1 : 0;
        added += r.densified.cloned + r.densified.split;
        stages.insert(r.stage);
    }
    EXPECT_EQ(densified, 2);
    EXPECT_GT(added, 100u);
    EXPECT_GT(resumed.state().model.size(), 1000u);
    EXPECT_EQ(stages.size(), 3u);

    for (std::size_t i = 0; i < 60; ++i) {
        const StepReport& a = straight_reports[60 + i];
        const StepReport& b = resumed_reports[i];
        ASSERT_EQ(a.iteration, b.iteration);
        EXPECT_EQ(a.view, b.view) << a.iteration;
        EXPECT_EQ(a.total, b.total) << a.iteration;
        EXPECT_EQ(a.psnr, b.psnr) << a.iteration;
        EXPECT_EQ(a.surfels, b.surfels) << a.iteration;
    }
    expect_same_state(straight.state(), resumed.state());
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
