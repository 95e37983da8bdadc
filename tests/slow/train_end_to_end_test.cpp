// End-to-end trainings of the training loop (train/trainer.h) on the tiny synthetic scene: the three stages
// lower the loss and raise the PSNR, the learned per-photo environments follow the true ones, and a
// paper-preset run resumed from a checkpoint is bit-exact. Slow tier: run in the release tree by
// scripts/test.sh (and CI); under the sanitizers TrainTrainer.ResumeIsBitExactWithTheSkyModel trains through
// every stage.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <numeric>
#include <set>
#include <string>
#include <vector>

#include "fast/trainer_test_util.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/sh_text.h"
#include "lumigauss/train/checkpoint.h"

namespace lumigauss {
namespace {

using namespace trainer_test;

double mean_of(const std::vector<StepReport>& reports, std::size_t first, std::size_t count,
               double StepReport::*field) {
    double sum = 0;
    for (std::size_t i = first; i < first + count; ++i) sum += reports[i].*field;
    return sum / double(count);
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

}  // namespace
}  // namespace lumigauss
