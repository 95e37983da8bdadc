// Adam against the torch.optim.Adam formula (by hand and by an independent double reference), the row
// operations used by densification, and the 3DGS log-linear learning-rate schedule.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "lumigauss/train/adam.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

// Per-element torch Adam in double, written from the documentation's pseudo-code:
// m = b1 m + (1-b1) g; v = b2 v + (1-b2) g^2; p -= lr * (m / (1-b1^t)) / (sqrt(v / (1-b2^t)) + eps).
struct RefAdam {
    double m = 0, v = 0;
    void step(double& p, double g, int t, double lr, double eps = 1e-15) {
        m = 0.9 * m + 0.1 * g;
        v = 0.999 * v + 0.001 * g * g;
        const double mhat = m / (1 - std::pow(0.9, t)), vhat = v / (1 - std::pow(0.999, t));
        p -= lr * mhat / (std::sqrt(vhat) + eps);
    }
};

TEST(TrainAdam, FirstTwoStepsByHand) {
    // Step 1: m = 0.1, v = 0.001, mhat = 1, vhat = 1 -> p = -lr. Step 2 with g = -1: m = -0.01,
    // v = 0.001999, mhat = -0.01 / 0.19, vhat = 1 -> p = -0.1 + 0.1 / 19.
    AdamGroup adam("x", 1, 0.1);
    std::vector<float> p = {0.0f};
    std::vector<float> g = {1.0f};
    adam.step(p, g);
    EXPECT_EQ(adam.step_count(), 1);
    EXPECT_NEAR(p[0], -0.1f, 1e-7);
    EXPECT_NEAR(adam.exp_avg()[0], 0.1f, 1e-8);
    EXPECT_NEAR(adam.exp_avg_sq()[0], 0.001f, 1e-10);
    g[0] = -1.0f;
    adam.step(p, g);
    EXPECT_NEAR(p[0], -0.1 + 0.1 / 19.0, 1e-7);
    EXPECT_NEAR(adam.exp_avg()[0], -0.01f, 1e-8);
    EXPECT_NEAR(adam.exp_avg_sq()[0], 0.001999f, 1e-9);
}

TEST(TrainAdam, EpsMattersOnlyForTinyGradients) {
    // With torch's default eps 1e-8 a gradient of 1e-9 moves the parameter by lr * 1e-9 / (1e-9 + 1e-8);
    // with 1e-15 (2DGS/3DGS) by almost lr.
    AdamGroup big_eps("a", 1, 1.0, 1, 1e-8), small_eps("b", 1, 1.0);
    std::vector<float> pa = {0.0f}, pb = {0.0f};
    const std::vector<float> g = {1e-9f};
    big_eps.step(pa, g);
    small_eps.step(pb, g);
    EXPECT_NEAR(pa[0], -1e-9 / (1e-9 + 1e-8), 1e-4);
    EXPECT_NEAR(pb[0], -1.0, 1e-5);
}

TEST(TrainAdam, ManyStepsMatchReference) {
    const std::size_t n = 7;
    AdamGroup adam("x", n, 0.01);
    std::vector<float> p(n);
    std::vector<double> pref(n);
    std::vector<RefAdam> ref(n);
    for (std::size_t i = 0; i < n; ++i) p[i] = float(0.3 * double(i) - 1.0), pref[i] = p[i];
    std::vector<float> g(n);
    for (int t = 1; t <= 50; ++t) {
        for (std::size_t i = 0; i < n; ++i) g[i] = float(std::sin(0.7 * t + double(i)) * (1.0 + double(i)));
        if (t % 10 == 0) g[2] = 0.0f;  // a zero gradient still advances moments (torch does the same)
        adam.step(p, g);
        for (std::size_t i = 0; i < n; ++i) ref[i].step(pref[i], g[i], t, 0.01);
    }
    EXPECT_EQ(adam.step_count(), 50);
    for (std::size_t i = 0; i < n; ++i) {
        EXPECT_NEAR(p[i], pref[i], 1e-5) << i;
        EXPECT_NEAR(adam.exp_avg()[i], ref[i].m, 1e-6) << i;
        EXPECT_NEAR(adam.exp_avg_sq()[i], ref[i].v, 1e-6) << i;
    }
}

TEST(TrainAdam, LearningRateChangesApplyToNextStep) {
    AdamGroup adam("x", 1, 0.1);
    std::vector<float> p = {0.0f};
    const std::vector<float> g = {2.0f};
    adam.set_lr(0.0);  // LumiGauss stage 2 sets env LRs to 0: moments still advance, parameters do not
    adam.step(p, g);
    EXPECT_EQ(p[0], 0.0f);
    EXPECT_EQ(adam.step_count(), 1);
    adam.set_lr(0.5);
    adam.step(p, g);
    EXPECT_NEAR(p[0], -0.5f, 1e-6);  // constant gradient: mhat / sqrt(vhat) = 1
}

TEST(TrainAdam, RejectsMismatchedSizes) {
    EXPECT_THROW(AdamGroup("x", 5, 0.1, 3), Error);
    AdamGroup adam("x", 3, 0.1, 3);
    std::vector<float> p(3), g(6);
    EXPECT_THROW(adam.step(p, g), Error);
    EXPECT_THROW(adam.keep_rows(std::vector<std::uint8_t>{1, 0}), Error);
    EXPECT_THROW(adam.duplicate_rows(std::vector<std::size_t>{1}), Error);
}

// The parameter array and the optimizer go through the same row edits; afterwards every row must carry its
// own history (checked against one reference state per element that travels with its row).
TEST(TrainAdam, RowOperationsKeepMomentsAligned) {
    constexpr int kW = 3;
    AdamGroup adam("xyz", 4 * kW, 0.01, kW);
    std::vector<float> p(4 * kW);
    std::vector<double> pref;
    std::vector<RefAdam> ref(4 * kW);
    for (std::size_t i = 0; i < p.size(); ++i) p[i] = float(i) * 0.1f;
    pref.assign(p.begin(), p.end());
    int t = 0;
    const auto step_all = [&](int salt) {
        ++t;
        std::vector<float> g(p.size());
        for (std::size_t i = 0; i < g.size(); ++i)
            g[i] = float(std::cos(double(i) * 1.3 + salt) + 0.1 * salt);
        adam.step(p, g);
        for (std::size_t i = 0; i < g.size(); ++i) ref[i].step(pref[i], g[i], t, 0.01);
    };
    step_all(1);
    step_all(2);

    // Densify: two new rows (zero moments), step count kept.
    adam.append_rows(2);
    for (int i = 0; i < 2 * kW; ++i) p.push_back(5.0f + float(i)), pref.push_back(5.0 + i), ref.push_back({});
    EXPECT_EQ(adam.rows(), 6u);
    EXPECT_EQ(adam.step_count(), 2);
    for (int i = 4 * kW; i < 6 * kW; ++i) EXPECT_EQ(adam.exp_avg()[i], 0.0f);

    // Prune rows 1 and 4.
    const std::vector<std::uint8_t> keep = {1, 0, 1, 1, 0, 1};
    adam.keep_rows(keep);
    keep_rows(p, kW, keep);
    std::vector<double> pref2;
    std::vector<RefAdam> ref2;
    for (std::size_t r = 0; r < keep.size(); ++r)
        if (keep[r])
            for (int i = 0; i < kW; ++i) pref2.push_back(pref[r * kW + i]), ref2.push_back(ref[r * kW + i]);
    pref = pref2, ref = ref2;
    ASSERT_EQ(adam.size(), p.size());
    ASSERT_EQ(adam.size(), pref.size());
    for (std::size_t i = 0; i < p.size(); ++i) EXPECT_NEAR(adam.exp_avg()[i], ref[i].m, 1e-7) << i;

    // Duplicate rows 2 and 0 (copies carry the moments), then zero row 1's moments.
    const std::vector<std::size_t> dup = {2, 0};
    adam.duplicate_rows(dup);
    append_copies_of_rows(p, kW, dup);
    for (std::size_t r : dup)
        for (int i = 0; i < kW; ++i) pref.push_back(pref[r * kW + i]), ref.push_back(ref[r * kW + i]);
    const std::vector<std::size_t> reset = {1};
    adam.reset_rows(reset);
    for (int i = 0; i < kW; ++i) ref[kW + i] = {};
    ASSERT_EQ(adam.rows(), 6u);

    step_all(3);
    step_all(4);
    for (std::size_t i = 0; i < p.size(); ++i) {
        EXPECT_NEAR(p[i], pref[i], 1e-5) << i;
        EXPECT_NEAR(adam.exp_avg()[i], ref[i].m, 1e-6) << i;
        EXPECT_NEAR(adam.exp_avg_sq()[i], ref[i].v, 1e-6) << i;
    }

    // Opacity-reset style: all moments zero, the step count stays.
    adam.reset_moments();
    for (float v : adam.exp_avg_sq()) EXPECT_EQ(v, 0.0f);
    EXPECT_EQ(adam.step_count(), 4);
}

TEST(TrainAdam, ExponLrScheduleEndpointsAndMidpoint) {
    const ExponLrSchedule s{1.6e-4, 1.6e-6, 0, 0.01, 30000};  // LumiGauss xyz (times the scene extent)
    EXPECT_NEAR(s(0), 1.6e-4, 1e-18);
    EXPECT_NEAR(s(30000), 1.6e-6, 1e-18);
    EXPECT_NEAR(s(40000), 1.6e-6, 1e-18);                      // constant after max_steps
    EXPECT_NEAR(s(15000), std::sqrt(1.6e-4 * 1.6e-6), 1e-17);  // log-linear: geometric mean halfway
    EXPECT_EQ(s(-1), 0.0);
    EXPECT_EQ((ExponLrSchedule{0.0, 0.0, 0, 1.0, 100})(5), 0.0);
}

TEST(TrainAdam, ExponLrScheduleDelay) {
    const ExponLrSchedule s{1e-2, 1e-4, 100, 0.01, 1000};
    EXPECT_NEAR(s(0), 0.01 * 1e-2, 1e-15);
    const double loglerp50 = std::exp(std::log(1e-2) * 0.95 + std::log(1e-4) * 0.05);
    EXPECT_NEAR(s(50), (0.01 + 0.99 * std::sin(std::numbers::pi / 4)) * loglerp50, 1e-15);
    const double loglerp500 = std::exp(std::log(1e-2) * 0.5 + std::log(1e-4) * 0.5);
    EXPECT_NEAR(s(500), loglerp500, 1e-15);  // past the delay: undamped
}

}  // namespace
}  // namespace lumigauss
