// The penalty on needle-shaped surfels (train/scale_ratio_penalty.h): its value and gradient, and that the
// trainer applies it (lambda_scale_ratio).
#include "lumigauss/train/scale_ratio_penalty.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "fast/trainer_test_util.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

// Surfels within the ratio cost nothing and get no gradient; beyond it, the excess of the log ratio.
TEST(ScaleRatioPenalty, KnownAnswer) {
    const std::vector<float> scales = {1.0f,  1.0f,   // round
                                       2.0f,  0.5f,   // ratio 4: within 10
                                       10.0f, 0.1f,   // ratio 100: excess log 10
                                       0.2f,  4.0f};  // ratio 20 the other way: excess log 2
    std::vector<float> grads(scales.size(), 0.0f);
    const double penalty = scale_ratio_penalty(scales, 10.0, 1.0, grads);
    EXPECT_NEAR(penalty, (std::log(10.0) + std::log(2.0)) / 4.0, 1e-6);
    for (int k = 0; k < 4; ++k) EXPECT_EQ(grads[std::size_t(k)], 0.0f) << k;
    // The long side is pulled in, the short side out, by weight / n / scale.
    EXPECT_NEAR(grads[4], 0.25 / 10.0, 1e-7);
    EXPECT_NEAR(grads[5], -0.25 / 0.1, 1e-6);
    EXPECT_NEAR(grads[6], -0.25 / 0.2, 1e-6);
    EXPECT_NEAR(grads[7], 0.25 / 4.0, 1e-7);
}

// The gradient is the finite difference of weight x penalty (central differences, away from the hinge).
TEST(ScaleRatioPenalty, GradientMatchesFiniteDifferences) {
    const std::vector<float> scales = {3.0f, 0.05f, 0.4f, 0.5f, 0.02f, 1.5f, 7.0f, 0.3f};
    const double weight = 0.7, max_ratio = 6.0;
    std::vector<float> grads(scales.size(), 0.0f);
    (void)scale_ratio_penalty(scales, max_ratio, weight, grads);
    for (std::size_t k = 0; k < scales.size(); ++k) {
        const float h = scales[k] * 1e-3f;
        std::vector<float> plus = scales, minus = scales, ignored(scales.size());
        plus[k] += h, minus[k] -= h;
        const double fd = weight *
                          (scale_ratio_penalty(plus, max_ratio, 1.0, ignored) -
                           scale_ratio_penalty(minus, max_ratio, 1.0, ignored)) /
                          (double(plus[k]) - double(minus[k]));
        EXPECT_NEAR(grads[k], fd, 1e-3 * std::abs(fd) + 1e-6) << "value " << k;
    }
}

// The pull adds to what the rasterizer's backward pass left in the gradient.
TEST(ScaleRatioPenalty, AddsToTheGradientItIsGiven) {
    const std::vector<float> scales = {5.0f, 0.1f};
    std::vector<float> grads = {1.0f, 2.0f};
    (void)scale_ratio_penalty(scales, 2.0, 1.0, grads);
    EXPECT_NEAR(grads[0], 1.0f + 1.0f / 5.0f, 1e-6);
    EXPECT_NEAR(grads[1], 2.0f - 1.0f / 0.1f, 1e-5);
}

TEST(ScaleRatioPenalty, EmptyModelAndMismatchedSizes) {
    std::vector<float> none;
    EXPECT_EQ(scale_ratio_penalty(none, 10.0, 1.0, none), 0.0);
    std::vector<float> odd = {1.0f}, two(2), scales = {1.0f, 2.0f};
    EXPECT_THROW((void)scale_ratio_penalty(odd, 10.0, 1.0, odd), Error);
    EXPECT_THROW((void)scale_ratio_penalty(scales, 10.0, 1.0, odd), Error);
}

// Median |log s_u - log s_v| over the model's surfels.
double median_log_ratio(const GaussianModel& model) {
    const std::vector<float>& raw = model.param(ModelParam::Scaling);  // log scales
    std::vector<double> r;
    for (std::size_t i = 0; i + 1 < raw.size(); i += 2) r.push_back(std::abs(double(raw[i]) - raw[i + 1]));
    std::nth_element(r.begin(), r.begin() + std::ptrdiff_t(r.size() / 2), r.end());
    return r[r.size() / 2];
}

// The trainer applies the penalty: every surfel of the tiny scene stretched to a ratio of e^4 (55) becomes
// rounder over 40 shadowed-stage steps with the key on, and stays as thin without it.
double median_log_ratio_after_training(double lambda) {
    TrainConfig c = trainer_test::shrunk_config();
    c.lambda_scale_ratio = lambda;
    c.max_scale_ratio = 4.0;
    Trainer t = trainer_test::make_trainer(c);
    std::vector<std::vector<float>> raw(kModelParamCount);
    for (ModelParam p : kAllModelParams) raw[int(p)] = t.state().model.param(p);
    std::vector<float>& scales = raw[int(ModelParam::Scaling)];
    for (std::size_t i = 0; i + 1 < scales.size(); i += 2) {
        const float mean = 0.5f * (scales[i] + scales[i + 1]);
        scales[i] = mean + 2.0f, scales[i + 1] = mean - 2.0f;
    }
    t.state().model =
        GaussianModel::from_raw(std::move(raw), t.state().scene_extent, model_learning_rates(c));
    t.state().iteration = c.start_shadowed + 10;  // after densification: the surfels stay the same
    EXPECT_NEAR(median_log_ratio(t.state().model), 4.0, 1e-5);
    const std::size_t surfels = t.state().model.size();
    for (int k = 0; k < 40; ++k) (void)t.step();
    EXPECT_EQ(t.state().model.size(), surfels);
    return median_log_ratio(t.state().model);
}

TEST(ScaleRatioPenalty, TrainingMakesStretchedSurfelsRounder) {
    const double without = median_log_ratio_after_training(0.0), with = median_log_ratio_after_training(1.0);
    // Adam moves each log scale by about lr_scaling (0.005) per step: 40 steps on both sides take the log
    // ratio down by up to 0.4.
    EXPECT_GT(without, 3.9);
    EXPECT_LT(with, without - 0.25);
}

}  // namespace
}  // namespace lumigauss
