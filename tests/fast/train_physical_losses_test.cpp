// The physical losses over a whole model (train/physical_losses.h; research/lumigauss_official.md 4.2, 4.3):
// the transfer losses l_[0,1], l_consistency, l_shadow over every surfel with counter-RNG directions, and
// the environment non-negativity l_+. The sampled directions are private to the library, so the values are
// checked by known answers (constant transfers), by their expectation under the official cube-normalised
// direction distribution (a deterministic quadrature over [-1,1]^3, compared within a few standard errors),
// and by inequalities; the gradients by central finite differences of the (fixed-direction) loss.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <span>
#include <utility>
#include <vector>

#include "lumigauss/model/view_shading.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/shading/surfel_shading.h"
#include "lumigauss/train/gaussian_model.h"
#include "lumigauss/train/physical_losses.h"
#include "support/finite_difference.h"

namespace lumigauss {
namespace {

using testing::central_difference;
double uni(std::mt19937_64& rng, double lo = -1.0, double hi = 1.0) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
}

Vec3d random_unit(std::mt19937_64& rng) {
    for (;;) {
        const Vec3d v{uni(rng), uni(rng), uni(rng)};
        const double len = length(v);
        if (len > 0.1 && len <= 1.0) return v / len;
    }
}

// A model whose every stored transfer value (both sides, all 3 channels) is junk of magnitude up to 5, so
// that reading a wrong side or channel shows; the caller then writes channel 0 of the sides in use.
GaussianModel junk_model(std::size_t n, std::mt19937_64& rng) {
    std::vector<std::vector<float>> raw(kModelParamCount);
    for (int p = 0; p < kModelParamCount; ++p)
        raw[std::size_t(p)].assign(n * std::size_t(GaussianModel::width(ModelParam(p))), 0.0f);
    for (std::size_t i = 0; i < n; ++i) raw[int(ModelParam::Rotation)][4 * i] = 1.0f;
    for (ModelParam p : {ModelParam::TransferPositive, ModelParam::TransferNegative})
        for (float& v : raw[int(p)]) v = float(5 * uni(rng));
    return GaussianModel::from_raw(std::move(raw), 1.0);
}

ModelParam side_param(bool positive) {
    return positive ? ModelParam::TransferPositive : ModelParam::TransferNegative;
}

void set_channel0(GaussianModel& m, bool positive, std::size_t i, const double t[kShCount]) {
    auto& v = m.param(side_param(positive));
    for (int k = 0; k < kShCount; ++k) v[i * kTransferStored + std::size_t(3 * k)] = float(t[k]);
}

// The channel-0 transfer of surfel i's side in use, as the library reads it (float -> double).
void used_channel0(const GaussianModel& m, const ViewNormals& vn, std::size_t i, double t[kShCount]) {
    const auto& v = m.param(side_param(vn.positive_side[i] != 0));
    for (int k = 0; k < kShCount; ++k) t[k] = double(v[i * kTransferStored + std::size_t(3 * k)]);
}

// Random unit normals, sides alternating.
ViewNormals random_normals(std::size_t n, std::mt19937_64& rng) {
    ViewNormals vn;
    for (std::size_t i = 0; i < n; ++i) {
        vn.normal.push_back(random_unit(rng).cast<float>());
        vn.positive_side.push_back(std::uint8_t(i % 2));
    }
    return vn;
}

// t(w) = value + small higher-order terms: |t - value| <= 0.05 * sum_k |Y_k| < 0.25 everywhere.
void near_constant_transfer(std::mt19937_64& rng, double value, double t[kShCount]) {
    for (int k = 0; k < kShCount; ++k) t[k] = 0.05 * uni(rng);
    t[0] = value / sh_const::kY00;
}

bool all_zero(std::span<const float> v) {
    return std::all_of(v.begin(), v.end(), [](float x) { return x == 0.0f; });
}

// ---------------------------------------------------------------------------------------------------------
// Expectations under the official direction distribution: u ~ U([-1,1]^3), w = u / |u|. Midpoint rule on
// an M^3 grid of the cube, i.e. the exact distribution up to quadrature error.

template <typename F>
void for_each_cube_direction(int m, F&& f) {
    const double h = 2.0 / m;
    for (int a = 0; a < m; ++a)
        for (int b = 0; b < m; ++b)
            for (int c = 0; c < m; ++c) {
                const Vec3d u{-1 + (a + 0.5) * h, -1 + (b + 0.5) * h, -1 + (c + 0.5) * h};
                f(u / length(u));
            }
}

// Per-direction moments of the transfer losses, summed over the grid (divide by the grid size).
struct TransferMoments {
    double cons = 0, cons2 = 0;                     // (t-c)^2 and its square
    double shadow = 0, shadow2 = 0;                 // max(0, t-c)^2 and its square
    double below_p = 0, below_a = 0, below_a2 = 0;  // 1(t<0), t^2 1(t<0), t^4 1(t<0)
    double above_p = 0, above_a = 0, above_a2 = 0;  // the same for t > 1 with (t-1)
    double count = 0;
    TransferMoments& operator+=(const TransferMoments& o) {
        cons += o.cons, cons2 += o.cons2, shadow += o.shadow, shadow2 += o.shadow2;
        below_p += o.below_p, below_a += o.below_a, below_a2 += o.below_a2;
        above_p += o.above_p, above_a += o.above_a, above_a2 += o.above_a2;
        count += o.count;
        return *this;
    }
};

TransferMoments grid_moments(const double t_sh[kShCount], Vec3d n, int m) {
    TransferMoments s;
    for_each_cube_direction(m, [&](Vec3d w) {
        double y[kShCount];
        sh_basis(w, y);
        double t = 0;
        for (int k = 0; k < kShCount; ++k) t += t_sh[k] * y[k];
        const double c = std::max(0.0, dot(n, w));
        const double d2 = (t - c) * (t - c);
        s.cons += d2, s.cons2 += d2 * d2;
        if (t > c) s.shadow += d2, s.shadow2 += d2 * d2;
        if (t < 0) s.below_p += 1, s.below_a += t * t, s.below_a2 += t * t * t * t;
        if (t > 1) {
            const double e = (t - 1) * (t - 1);
            s.above_p += 1, s.above_a += e, s.above_a2 += e * e;
        }
        s.count += 1;
    });
    return s;
}

// Expected value and standard error of a penalize_outside_range term (sum of a over violating samples
// divided by their count, pooled over N samples), by the delta method.
struct Estimate {
    double mean = 0, sigma = 0;
};
Estimate ratio_estimate(double p, double a, double a2, double n_samples) {
    if (p <= 0) return {};
    const double r = a / p;
    const double var = a2 - 2 * r * a * 1.0 + r * r * p;  // E[(a - r b)^2] with b = 1(violating), a b = a
    return {r, std::sqrt(std::max(var, 0.0) / n_samples) / p};
}
Estimate mean_estimate(double x, double x2, double n_samples) {
    return {x, std::sqrt(std::max(x2 - x * x, 0.0) / n_samples)};
}

// ---------------------------------------------------------------------------------------------------------
// model_transfer_losses: values

constexpr TransferLossWeights<double> kAllWeights{0.3, 1.7, 2.3};

TEST(TrainPhysicalLossesTransfer, KnownAnswersForConstantTransfers) {
    std::mt19937_64 rng(1);
    const int samples = 25;
    // t(w) == a exactly when only the DC coefficient is set: T_0 = a / Y00.
    auto constant_model = [&](const std::vector<double>& values, ViewNormals& vn) {
        GaussianModel m = junk_model(values.size(), rng);
        vn = random_normals(values.size(), rng);
        for (std::size_t i = 0; i < values.size(); ++i) {
            double t[kShCount]{};
            t[0] = values[i] / sh_const::kY00;
            set_channel0(m, vn.positive_side[i] != 0, i, t);
        }
        return m;
    };
    ViewNormals vn;
    {
        // All samples below 0 (t = -0.5) or above 1 (t = 1.5): each mean is over its own violating
        // samples, so l_[0,1] = 0.25 + 0.25. Below 0, t < c always: those surfels add no shadow loss.
        GaussianModel m = constant_model({-0.5, 1.5, -0.5, 1.5, -0.5, 1.5}, vn);
        const TransferLossResult r = model_transfer_losses(m, vn, samples, 7, 100, kAllWeights, false);
        EXPECT_NEAR(r.losses.range01, 0.5, 1e-6);
        EXPECT_GT(r.losses.consistency, r.losses.shadow);
        EXPECT_GT(r.losses.shadow, 0.0);
        EXPECT_NEAR(r.weighted, 0.3 * r.losses.range01 + 1.7 * r.losses.consistency + 2.3 * r.losses.shadow,
                    1e-12 * r.weighted);
    }
    {
        // The means are pooled over all surfels, over the violating samples only: one surfel at t = -1
        // among three at t = 0.5 still gives 1, not 1/4.
        GaussianModel m = constant_model({0.5, -1.0, 0.5, 0.5}, vn);
        const TransferLossResult r = model_transfer_losses(m, vn, samples, 7, 100, kAllWeights, false);
        EXPECT_NEAR(r.losses.range01, 1.0, 1e-6);
    }
    {
        // t = 1.5 > 1 >= c everywhere: max(0, t - c) = t - c, so l_shadow == l_consistency, and
        // (1.5 - c)^2 lies in [0.25, 2.25].
        GaussianModel m = constant_model({1.5, 1.5, 1.5}, vn);
        const TransferLossResult r = model_transfer_losses(m, vn, samples, 7, 100, kAllWeights, false);
        EXPECT_NEAR(r.losses.shadow, r.losses.consistency, 1e-12);
        EXPECT_GT(r.losses.consistency, 0.25);
        EXPECT_LT(r.losses.consistency, 2.25);
        EXPECT_NEAR(r.losses.range01, 0.25, 1e-6);
    }
    {
        // t = -0.5: l_[0,1] = mean t^2 = 0.25 and dl/dT_0 = sum_s 2 t Y00 / (n S) = -Y00 / n per surfel;
        // nothing from consistency or shadow when their weights are 0. Only channel 0 of the side in use.
        const std::size_t n = 5;
        GaussianModel m = constant_model(std::vector<double>(n, -0.5), vn);
        m.zero_grad();
        const TransferLossResult r =
            model_transfer_losses(m, vn, samples, 7, 100, TransferLossWeights<double>{1.0, 0.0, 0.0}, true);
        EXPECT_NEAR(r.losses.range01, 0.25, 1e-6);
        EXPECT_NEAR(r.weighted, 0.25, 1e-6);
        const GaussianModel& cm = m;
        for (std::size_t i = 0; i < n; ++i) {
            const bool positive = vn.positive_side[i] != 0;
            EXPECT_NEAR(cm.grad(side_param(positive))[i * kTransferStored], -sh_const::kY00 / double(n), 1e-6)
                << i;
            EXPECT_EQ(cm.grad(side_param(!positive))[i * kTransferStored], 0.0f) << i;
        }
    }
}

TEST(TrainPhysicalLossesTransfer, RangeLossZeroInsideUnitIntervalAndShadowBelowConsistency) {
    std::mt19937_64 rng(2);
    const std::size_t n = 50;
    GaussianModel m = junk_model(n, rng);
    const ViewNormals vn = random_normals(n, rng);
    for (std::size_t i = 0; i < n; ++i) {
        double t[kShCount];
        near_constant_transfer(rng, uni(rng, 0.3, 0.7), t);  // t(w) in (0.05, 0.95)
        set_channel0(m, vn.positive_side[i] != 0, i, t);
    }
    const TransferLossResult r = model_transfer_losses(m, vn, 25, 3, 5, kAllWeights, false);
    EXPECT_EQ(r.losses.range01, 0.0);
    EXPECT_GT(r.losses.consistency, 0.0);
    EXPECT_LE(r.losses.shadow, r.losses.consistency);
    EXPECT_GT(r.losses.shadow, 0.0);

    // Wide random transfers: still l_shadow <= l_consistency, now l_[0,1] > 0.
    for (std::size_t i = 0; i < n; ++i) {
        double t[kShCount];
        for (double& v : t) v = 1.5 * uni(rng);
        set_channel0(m, vn.positive_side[i] != 0, i, t);
    }
    const TransferLossResult w = model_transfer_losses(m, vn, 25, 3, 5, kAllWeights, false);
    EXPECT_GT(w.losses.range01, 0.0);
    EXPECT_LE(w.losses.shadow, w.losses.consistency);
}

// A transfer equal to the SH projection of max(0, n.w) (cosine_lobe_sh) differs from the clamped cosine
// only by its degree-2 truncation error. Over the uniform sphere that mean squared error is
//   (|c|^2 - |P2 c|^2) / 4pi,  |c|^2 = 2pi/3,  |P2 c|^2 = sum_l A_l^2 (2l+1) / 4pi = pi (1 + 4/3 + 5/16) / 4,
// i.e. exactly 1/768 = 1.3021e-3. The official directions are cube-normalised; their density relative to
// uniform is pi r^3 / 6 with r = 1 / |w|_inf in [1, sqrt 3], i.e. in [0.524, 2.721], which bounds the
// expectation.
TEST(TrainPhysicalLossesTransfer, CosineLobeConsistencyIsTheProjectionError) {
    const double pi = std::numbers::pi;
    const double uniform_error = (2 * pi / 3 - pi * (1 + 4.0 / 3 + 5.0 / 16) / 4) / (4 * pi);
    EXPECT_NEAR(uniform_error, 1.0 / 768, 1e-15);  // = (128 - 127) / (192 * 4)
    const double lo = pi / 6 * uniform_error, hi = pi * 3 * std::sqrt(3.0) / 6 * uniform_error;

    std::mt19937_64 rng(3);
    const std::size_t n = 64;
    const int samples = 128;
    GaussianModel m = junk_model(n, rng);
    const ViewNormals vn = random_normals(n, rng);
    TransferMoments total;
    for (std::size_t i = 0; i < n; ++i) {
        float lobe[kShCount];
        cosine_lobe_sh(vn.normal[i], lobe);
        double t[kShCount];
        for (int k = 0; k < kShCount; ++k) t[k] = double(lobe[k]);
        set_channel0(m, vn.positive_side[i] != 0, i, t);
        total += grid_moments(t, vn.normal[i].cast<double>(), 24);
    }
    const TransferLossResult r = model_transfer_losses(m, vn, samples, 11, 0, kAllWeights, false);
    EXPECT_GT(r.losses.consistency, lo);
    EXPECT_LT(r.losses.consistency, hi);
    EXPECT_LE(r.losses.shadow, r.losses.consistency);
    // And against the expectation itself.
    const double n_samples = double(n) * samples;
    const Estimate e = mean_estimate(total.cons / total.count, total.cons2 / total.count, n_samples);
    EXPECT_NEAR(r.losses.consistency, e.mean, 5 * e.sigma + 0.02 * e.mean);
    // The lobe dips slightly below 0 (min 0.09375 - 0.5^2 / (4 * 0.46875) = -0.040 on the sphere) and
    // rises to 1.0625 at the normal: l_[0,1] is small but not zero.
    EXPECT_GT(r.losses.range01, 0.0);
    EXPECT_LT(r.losses.range01, 0.0625 * 0.0625 + 0.04 * 0.04);
}

// All three values against their expectations under the official direction distribution.
TEST(TrainPhysicalLossesTransfer, ValuesMatchExpectationOverCubeNormalisedDirections) {
    std::mt19937_64 rng(4);
    const std::size_t n = 24;
    const int samples = 400;
    GaussianModel m = junk_model(n, rng);
    const ViewNormals vn = random_normals(n, rng);
    TransferMoments total;
    for (std::size_t i = 0; i < n; ++i) {
        double t[kShCount];
        cosine_lobe_sh(vn.normal[i].cast<double>(), t);
        const double s = uni(rng, 0.7, 1.5);
        for (double& v : t) v = s * v + 0.15 * uni(rng);
        set_channel0(m, vn.positive_side[i] != 0, i, t);
        double tf[kShCount];
        used_channel0(m, vn, i, tf);
        total += grid_moments(tf, vn.normal[i].cast<double>(), 48);
    }
    const TransferLossResult r = model_transfer_losses(m, vn, samples, 12, 34, kAllWeights, false);
    const double N = double(n) * samples, g = total.count;
    const Estimate cons = mean_estimate(total.cons / g, total.cons2 / g, N);
    const Estimate shadow = mean_estimate(total.shadow / g, total.shadow2 / g, N);
    const Estimate below = ratio_estimate(total.below_p / g, total.below_a / g, total.below_a2 / g, N);
    const Estimate above = ratio_estimate(total.above_p / g, total.above_a / g, total.above_a2 / g, N);
    ASSERT_GT(below.mean, 0.0);
    ASSERT_GT(above.mean, 0.0);
    EXPECT_NEAR(r.losses.consistency, cons.mean, 5 * cons.sigma + 0.01 * cons.mean);
    EXPECT_NEAR(r.losses.shadow, shadow.mean, 5 * shadow.sigma + 0.01 * shadow.mean);
    const double range = below.mean + above.mean;
    EXPECT_NEAR(r.losses.range01, range, 5 * (below.sigma + above.sigma) + 0.02 * range);
}

// Directions are keyed by (seed, iteration, surfel): reproducible, different per iteration and per seed,
// and the same with one thread or several (the model is large enough for several reduction chunks).
TEST(TrainPhysicalLossesTransfer, DeterministicPerSeedAndIterationAndThreadCount) {
    std::mt19937_64 rng(5);
    const std::size_t n = 10000;
    GaussianModel a = junk_model(n, rng);
    const ViewNormals vn = random_normals(n, rng);
    for (std::size_t i = 0; i < n; ++i) {
        double t[kShCount];
        for (double& v : t) v = uni(rng);
        set_channel0(a, vn.positive_side[i] != 0, i, t);
    }
    GaussianModel b = a;
    const int samples = 4;
    TransferLossResult ra, rb;
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        a.zero_grad();
        ra = model_transfer_losses(a, vn, samples, 99, 1234, kAllWeights, true);
    }
    {
        tbb::global_control several(tbb::global_control::max_allowed_parallelism, 4);
        b.zero_grad();
        rb = model_transfer_losses(b, vn, samples, 99, 1234, kAllWeights, true);
    }
    EXPECT_EQ(ra.losses.range01, rb.losses.range01);
    EXPECT_EQ(ra.losses.consistency, rb.losses.consistency);
    EXPECT_EQ(ra.losses.shadow, rb.losses.shadow);
    EXPECT_EQ(ra.weighted, rb.weighted);
    const GaussianModel &ca = a, &cb = b;
    for (ModelParam p : {ModelParam::TransferPositive, ModelParam::TransferNegative}) {
        const auto x = ca.grad(p), y = cb.grad(p);
        EXPECT_TRUE(std::equal(x.begin(), x.end(), y.begin(), y.end()));
    }

    const TransferLossResult again = model_transfer_losses(a, vn, samples, 99, 1234, kAllWeights, false);
    EXPECT_EQ(again.losses.consistency, ra.losses.consistency);
    EXPECT_EQ(again.losses.range01, ra.losses.range01);
    const TransferLossResult next = model_transfer_losses(a, vn, samples, 99, 1235, kAllWeights, false);
    EXPECT_NE(next.losses.consistency, ra.losses.consistency);
    EXPECT_NE(next.losses.range01, ra.losses.range01);
    const TransferLossResult other_seed = model_transfer_losses(a, vn, samples, 98, 1234, kAllWeights, false);
    EXPECT_NE(other_seed.losses.consistency, ra.losses.consistency);
    // Fresh directions, same distribution: the values stay close.
    EXPECT_NEAR(next.losses.consistency, ra.losses.consistency, 0.05 * ra.losses.consistency);
}

// The official directions are cube-normalised, not uniform on the sphere (4.2). A degree-2 transfer peaked on
// the cube diagonals, t = 1.5 (xy + yz + zx), and the normal +z separate the two distributions by 10-20 %
// in l_consistency and l_shadow; with 40000 samples that is far beyond the sampling error.
TEST(TrainPhysicalLossesTransfer, DirectionsAreCubeNormalisedNotUniform) {
    std::mt19937_64 rng(9);
    const std::size_t n = 100;
    const int samples = 400;
    GaussianModel m = junk_model(n, rng);
    ViewNormals vn;
    double t[kShCount]{};
    t[4] = t[5] = t[7] = 1.5 / sh_const::kY2;  // Y4 = kY2 xy, Y5 = kY2 yz, Y7 = kY2 xz
    for (std::size_t i = 0; i < n; ++i) {
        vn.normal.push_back(Vec3f{0, 0, 1});
        vn.positive_side.push_back(std::uint8_t(i % 2));
        set_channel0(m, i % 2 != 0, i, t);
    }
    double tf[kShCount];
    used_channel0(m, vn, 0, tf);
    const TransferMoments cube = grid_moments(tf, Vec3d{0, 0, 1}, 48);
    // Uniform on the sphere: z uniform in [-1, 1] and phi uniform (Archimedes), midpoint rule.
    double u_cons = 0, u_shadow = 0, u_count = 0;
    const int K = 300;
    for (int a = 0; a < K; ++a) {
        const double z = -1 + (a + 0.5) * 2.0 / K, r = std::sqrt(1 - z * z);
        for (int b = 0; b < K; ++b) {
            const double phi = 2 * std::numbers::pi * (b + 0.5) / K;
            const Vec3d w{r * std::cos(phi), r * std::sin(phi), z};
            double y[kShCount];
            sh_basis(w, y);
            double tv = 0;
            for (int k = 0; k < kShCount; ++k) tv += tf[k] * y[k];
            const double d = tv - std::max(0.0, w.z);
            u_cons += d * d, u_shadow += d > 0 ? d * d : 0.0, u_count += 1;
        }
    }
    const double N = double(n) * samples;
    const Estimate cons = mean_estimate(cube.cons / cube.count, cube.cons2 / cube.count, N);
    const Estimate shadow = mean_estimate(cube.shadow / cube.count, cube.shadow2 / cube.count, N);
    // Precondition: the two distributions are distinguishable at this sample size.
    ASSERT_GT(std::fabs(u_cons / u_count - cons.mean), 10 * cons.sigma);
    ASSERT_GT(std::fabs(u_shadow / u_count - shadow.mean), 10 * shadow.sigma);
    const TransferLossResult r = model_transfer_losses(m, vn, samples, 21, 22, kAllWeights, false);
    EXPECT_NEAR(r.losses.consistency, cons.mean, 4 * cons.sigma + 0.005 * cons.mean);
    EXPECT_NEAR(r.losses.shadow, shadow.mean, 4 * shadow.sigma + 0.005 * shadow.mean);
}

// Values and gradients pooled over several reduction chunks (4096 surfels each): surfels of the first
// chunk at t = 0.5 (inside [0, 1]), the others at t = -1: l_[0,1] = 1 exactly, and with only its weight
// dl/dT_0 = sum_s 2 t Y00 / count = -2 Y00 / (number of surfels at t = -1) for each of those.
TEST(TrainPhysicalLossesTransfer, KnownAnswersOverSeveralChunks) {
    std::mt19937_64 rng(10);
    const std::size_t n = 10000, inside = 4096;
    const int samples = 3;
    GaussianModel m = junk_model(n, rng);
    const ViewNormals vn = random_normals(n, rng);
    for (std::size_t i = 0; i < n; ++i) {
        double t[kShCount]{};
        t[0] = (i < inside ? 0.5 : -1.0) / sh_const::kY00;
        set_channel0(m, vn.positive_side[i] != 0, i, t);
    }
    m.zero_grad();
    const TransferLossResult r =
        model_transfer_losses(m, vn, samples, 1, 1, TransferLossWeights<double>{1.0, 0.0, 0.0}, true);
    EXPECT_NEAR(r.losses.range01, 1.0, 1e-6);
    const GaussianModel& cm = m;
    const double expect = -2 * sh_const::kY00 / double(n - inside);
    for (std::size_t i = 0; i < n; ++i) {
        const float g = cm.grad(side_param(vn.positive_side[i] != 0))[i * kTransferStored];
        if (i < inside) {
            ASSERT_EQ(g, 0.0f) << i;
        } else {
            ASSERT_NEAR(g, expect, 1e-6 * std::fabs(expect)) << i;
        }
    }
}

// ---------------------------------------------------------------------------------------------------------
// model_transfer_losses: gradient

// Three groups of surfels: t(w) in (-0.75, -0.25) (every sample below 0), in (1.25, 1.75) (every sample
// above 1) and in (0.25, 0.75) (none outside [0, 1]), so the violating sets (and their counts) cannot change
// under the steps below. Then l_[0,1] and l_consistency are exactly quadratic in the transfer, and central
// differences are exact up to rounding for any step: a large step (0.03, moving t by < 0.02) makes the
// float rounding of the forward pass negligible and allows a tight tolerance. l_shadow adds the C1 kinks of
// max(0, t - c)^2: a smaller step and a looser tolerance.
struct FdCase {
    TransferLossWeights<double> weights;
    double step, rel_tol, abs_tol;
};

TEST(TrainPhysicalLossesTransfer, GradientMatchesFiniteDifferences) {
    std::mt19937_64 rng(6);
    const std::size_t n = 12;
    const int samples = 16;
    const std::uint64_t seed = 17;
    const std::int64_t iteration = 4242;
    GaussianModel m = junk_model(n, rng);
    const ViewNormals vn = random_normals(n, rng);
    const double centres[3] = {-0.5, 1.5, 0.5};
    for (std::size_t i = 0; i < n; ++i) {
        double t[kShCount];
        near_constant_transfer(rng, centres[i % 3], t);
        set_channel0(m, vn.positive_side[i] != 0, i, t);
    }
    for (const FdCase& fc :
         {FdCase{{0.3, 1.7, 0.0}, 0.03, 2e-4, 2e-6}, FdCase{kAllWeights, 3e-3, 2e-3, 1e-4}}) {
        SCOPED_TRACE(fc.weights.shadow == 0 ? "range01 + consistency" : "all three");
        m.zero_grad();
        const TransferLossResult r = model_transfer_losses(m, vn, samples, seed, iteration, fc.weights, true);
        ASSERT_GT(r.losses.range01, 0.0);
        ASSERT_GT(r.losses.shadow, 0.0);
        const auto loss = [&] {
            return model_transfer_losses(m, vn, samples, seed, iteration, fc.weights, false).weighted;
        };
        EXPECT_EQ(loss(), r.weighted);
        const GaussianModel& cm = m;
        int checked = 0;
        double max_g = 0;
        for (ModelParam p : {ModelParam::TransferPositive, ModelParam::TransferNegative}) {
            EXPECT_TRUE(cm.has_grad(p));
            for (std::size_t i = 0; i < n; ++i) {
                const bool in_use = (vn.positive_side[i] != 0) == (p == ModelParam::TransferPositive);
                for (int k = 0; k < kTransferStored; ++k) {
                    const std::size_t j = i * kTransferStored + std::size_t(k);
                    const double g = cm.grad(p)[j];
                    const double fd = central_difference(m.param(p)[j], fc.step, loss);
                    if (in_use && k % 3 == 0) {
                        EXPECT_NEAR(g, fd, fc.rel_tol * std::fabs(fd) + fc.abs_tol)
                            << "surfel " << i << " coeff " << k / 3;
                        max_g = std::max(max_g, std::fabs(g));
                        ++checked;
                    } else {
                        // Other channels and the side not in use: no dependence, no gradient.
                        EXPECT_EQ(g, 0.0) << "surfel " << i << " stored " << k << " in use " << in_use;
                        EXPECT_EQ(fd, 0.0) << "surfel " << i << " stored " << k << " in use " << in_use;
                    }
                }
            }
        }
        EXPECT_EQ(checked, int(n) * kShCount);
        EXPECT_GT(max_g, 0.05);
        for (ModelParam p : {ModelParam::Xyz, ModelParam::Rotation, ModelParam::Albedo})
            EXPECT_FALSE(cm.has_grad(p));
    }
}

// Each weight alone on wide random transfers (sample counts of l_[0,1] may change under a step there: the
// loss is only piecewise smooth, so a few entries may disagree).
TEST(TrainPhysicalLossesTransfer, GradientMatchesFiniteDifferencesPerTermOnWideTransfers) {
    std::mt19937_64 rng(7);
    const std::size_t n = 10;
    const int samples = 20;
    GaussianModel m = junk_model(n, rng);
    const ViewNormals vn = random_normals(n, rng);
    for (std::size_t i = 0; i < n; ++i) {
        double t[kShCount];
        for (double& v : t) v = uni(rng);
        t[0] += 1.5;
        set_channel0(m, vn.positive_side[i] != 0, i, t);
    }
    for (const TransferLossWeights<double> w :
         {TransferLossWeights<double>{0.8, 0, 0}, TransferLossWeights<double>{0, 0.8, 0},
          TransferLossWeights<double>{0, 0, 0.8}}) {
        m.zero_grad();
        model_transfer_losses(m, vn, samples, 5, 6, w, true);
        const auto loss = [&] { return model_transfer_losses(m, vn, samples, 5, 6, w, false).weighted; };
        const GaussianModel& cm = m;
        int bad = 0, total = 0;
        double max_g = 0;
        for (std::size_t i = 0; i < n; ++i) {
            const ModelParam p = side_param(vn.positive_side[i] != 0);
            for (int k = 0; k < kShCount; ++k) {
                const std::size_t j = i * kTransferStored + std::size_t(3 * k);
                const double g = cm.grad(p)[j];
                const double fd = central_difference(m.param(p)[j], 3e-3, loss);
                max_g = std::max(max_g, std::fabs(g));
                bad += std::fabs(g - fd) > 1e-2 * std::fabs(fd) + 2e-4;
                ++total;
            }
        }
        EXPECT_GT(max_g, 1e-3);
        EXPECT_LE(bad, total / 30) << "range01 " << w.range01 << " consistency " << w.consistency;
    }
}

TEST(TrainPhysicalLossesTransfer, NoGradientWithoutBackwardOrWeights) {
    std::mt19937_64 rng(8);
    const std::size_t n = 20;
    GaussianModel m = junk_model(n, rng);
    const ViewNormals vn = random_normals(n, rng);
    m.zero_grad();
    const TransferLossResult off = model_transfer_losses(m, vn, 25, 1, 2, kAllWeights, false);
    const TransferLossResult zero_w = model_transfer_losses(m, vn, 25, 1, 2, {}, true);
    const GaussianModel& cm = m;
    for (ModelParam p : {ModelParam::TransferPositive, ModelParam::TransferNegative}) {
        EXPECT_FALSE(cm.has_grad(p));
        EXPECT_TRUE(all_zero(cm.grad(p)));
    }
    // The values do not depend on the flag or the weights; the weighted sum does.
    const TransferLossResult on = model_transfer_losses(m, vn, 25, 1, 2, kAllWeights, true);
    EXPECT_EQ(off.losses.consistency, on.losses.consistency);
    EXPECT_EQ(zero_w.losses.consistency, on.losses.consistency);
    EXPECT_EQ(zero_w.losses.range01, on.losses.range01);
    EXPECT_EQ(zero_w.weighted, 0.0);
    EXPECT_EQ(off.weighted, on.weighted);
    EXPECT_TRUE(cm.has_grad(ModelParam::TransferPositive));

    // Gradients accumulate: a second call doubles them.
    const std::span<const float> g_neg = cm.grad(ModelParam::TransferNegative);
    const std::vector<float> once(g_neg.begin(), g_neg.end());
    model_transfer_losses(m, vn, 25, 1, 2, kAllWeights, true);
    for (std::size_t j = 0; j < once.size(); ++j)
        EXPECT_EQ(cm.grad(ModelParam::TransferNegative)[j], 2.0f * once[j]) << j;
}

// ---------------------------------------------------------------------------------------------------------
// env_nonnegativity_loss

ShCoeffs<float> random_env(std::mt19937_64& rng, double dc, double spread) {
    ShCoeffs<float> env;
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) env.c[k][c] = float(spread * uni(rng));
    for (int c = 0; c < 3; ++c) env.c[0][c] += float(dc);
    return env;
}

ShCoeffs<float> filled(float v) {
    ShCoeffs<float> g;
    for (auto& c : g.c) c = {v, v + 1, v + 2};
    return g;
}

TEST(TrainPhysicalLossesEnv, ZeroForPositiveEnvironment) {
    std::mt19937_64 rng(21);
    // Radiance = 5 Y00 (1.41) + at most 0.1 * sum |Y_k| (0.43) > 0 in every direction.
    const ShCoeffs<float> env = random_env(rng, 5.0, 0.1);
    ShCoeffs<float> g = filled(0.5f);
    const double l = env_nonnegativity_loss(env, 1000, 1, 2, 0.7, g);
    EXPECT_EQ(l, 0.0);
    const ShCoeffs<float> expect = filled(0.5f);
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) EXPECT_EQ(g.c[k][c], expect.c[k][c]);
}

TEST(TrainPhysicalLossesEnv, KnownAnswerForConstantRadiance) {
    // Radiance (-1, 2, -3) in every direction: the negative values are -1 and -3, as many of each, so the
    // mean of v^2 over them is 5; dl/dL_0 = sum 2 v Y00 / count = (-Y00, 0, -3 Y00), times the weight.
    ShCoeffs<float> env;
    env.c[0] = Vec3d{-1 / sh_const::kY00, 2 / sh_const::kY00, -3 / sh_const::kY00}.cast<float>();
    for (const double weight : {0.7, 3.0}) {
        ShCoeffs<float> g;
        const double l = env_nonnegativity_loss(env, 10, 4, 5, weight, g);
        EXPECT_NEAR(l, 5.0, 1e-5);  // unweighted
        EXPECT_NEAR(g.c[0][0], -weight * sh_const::kY00, 1e-6 * weight);
        EXPECT_EQ(g.c[0][1], 0.0f);
        EXPECT_NEAR(g.c[0][2], -3 * weight * sh_const::kY00, 1e-6 * weight);
        for (int k = 0; k < kShCount; ++k) EXPECT_EQ(g.c[k][1], 0.0f) << k;  // channel 1 never negative
    }
}

TEST(TrainPhysicalLossesEnv, PositiveForNegativeLobesAndMatchesExpectation) {
    std::mt19937_64 rng(22);
    const ShCoeffs<float> env = random_env(rng, 0.3, 0.6);
    const int samples = 4000;
    ShCoeffs<float> g;
    const double l = env_nonnegativity_loss(env, samples, 9, 10, 1.0, g);
    EXPECT_GT(l, 0.0);
    // Expectation: per channel, ratio of sum v^2 1(v<0) to count over the cube-normalised distribution,
    // pooled over the three channels.
    double p = 0, a = 0, a2 = 0, count = 0;
    const ShCoeffs<double> envd = env.cast<double>();
    for_each_cube_direction(48, [&](Vec3d w) {
        const Vec3d v = eval_sh(envd, w);
        for (int c = 0; c < 3; ++c)
            if (v[c] < 0) p += 1, a += v[c] * v[c], a2 += v[c] * v[c] * v[c] * v[c];
        count += 3;  // per-value probabilities
    });
    const Estimate e = ratio_estimate(p / count, a / count, a2 / count, 3.0 * samples);
    EXPECT_NEAR(l, e.mean, 5 * e.sigma + 0.02 * e.mean);
}

// As for the transfer losses, the env directions are cube-normalised (4.3): radiance negative near the cube
// diagonals in channel 0 (where the cube-normalised density is highest, up to 2.7x uniform) and weakly
// negative near the z axis in channel 1 (density down to 0.52x) gives a pooled mean that separates the two
// distributions by > 20 standard errors at 20000 directions.
TEST(TrainPhysicalLossesEnv, DirectionsAreCubeNormalisedNotUniform) {
    ShCoeffs<float> env;
    env.c[0] = Vec3d{0.5 / sh_const::kY00, 0.5 / sh_const::kY00, 1 / sh_const::kY00}.cast<float>();
    env.c[4][0] = env.c[5][0] = env.c[7][0] = float(-3 / sh_const::kY2);  // -3 (xy + yz + zx)
    env.c[6][1] = float(-0.3 / sh_const::kY20);                           // -0.3 (3 z^2 - 1)
    const ShCoeffs<double> envd = env.cast<double>();
    struct Acc {
        double p = 0, a = 0, a2 = 0, count = 0;
        void add(Vec3d v) {
            for (int c = 0; c < 3; ++c) {
                if (v[c] < 0) p += 1, a += v[c] * v[c], a2 += v[c] * v[c] * v[c] * v[c];
                count += 1;
            }
        }
    } cube, uniform;
    for_each_cube_direction(48, [&](Vec3d w) { cube.add(eval_sh(envd, w)); });
    const int K = 300;
    for (int i = 0; i < K; ++i) {
        const double z = -1 + (i + 0.5) * 2.0 / K, r = std::sqrt(1 - z * z);
        for (int j = 0; j < K; ++j) {
            const double phi = 2 * std::numbers::pi * (j + 0.5) / K;
            uniform.add(eval_sh(envd, Vec3d{r * std::cos(phi), r * std::sin(phi), z}));
        }
    }
    const int samples = 20000;
    const Estimate e =
        ratio_estimate(cube.p / cube.count, cube.a / cube.count, cube.a2 / cube.count, 3.0 * samples);
    ASSERT_GT(std::fabs(uniform.a / uniform.p - e.mean), 15 * e.sigma);  // precondition
    ShCoeffs<float> g;
    const double l = env_nonnegativity_loss(env, samples, 31, 32, 0.0, g);
    EXPECT_NEAR(l, e.mean, 5 * e.sigma + 0.01 * e.mean);
}

TEST(TrainPhysicalLossesEnv, GradientMatchesFiniteDifferences) {
    std::mt19937_64 rng(23);
    ShCoeffs<float> env = random_env(rng, 0.3, 0.6);
    const int samples = 50;
    const double weight = 0.7;
    ShCoeffs<float> g;
    const double l = env_nonnegativity_loss(env, samples, 13, 14, weight, g);
    ASSERT_GT(l, 0.0);
    const auto loss = [&] {
        ShCoeffs<float> unused;
        return env_nonnegativity_loss(env, samples, 13, 14, 0.0, unused);
    };
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) {
            const double fd = weight * central_difference(env.c[k][c], 1e-5, loss);
            EXPECT_NEAR(g.c[k][c], fd, 1e-4 * std::fabs(fd) + 1e-6) << k << " " << c;
        }
}

TEST(TrainPhysicalLossesEnv, WeightScalesGradientNotValueAndGradientAccumulates) {
    std::mt19937_64 rng(24);
    const ShCoeffs<float> env = random_env(rng, 0.0, 1.0);
    ShCoeffs<float> g1, g2 = filled(0.25f), g0 = filled(0.25f);
    const double l1 = env_nonnegativity_loss(env, 10, 1, 1, 0.7, g1);
    const double l2 = env_nonnegativity_loss(env, 10, 1, 1, 1.4, g2);
    const double l0 = env_nonnegativity_loss(env, 10, 1, 1, 0.0, g0);
    ASSERT_GT(l1, 0.0);
    EXPECT_EQ(l1, l2);
    EXPECT_EQ(l1, l0);
    const ShCoeffs<float> base = filled(0.25f);
    double max_g = 0;
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(g2.c[k][c] - base.c[k][c], 2 * g1.c[k][c], 1e-6) << k << " " << c;  // added, scaled
            EXPECT_EQ(g0.c[k][c], base.c[k][c]);  // weight 0: untouched
            max_g = std::max(max_g, double(std::fabs(g1.c[k][c])));
        }
    EXPECT_GT(max_g, 1e-3);
    // Same seed and iteration: same value; another iteration: other directions.
    ShCoeffs<float> unused;
    EXPECT_EQ(env_nonnegativity_loss(env, 10, 1, 1, 0.7, unused), l1);
    EXPECT_NE(env_nonnegativity_loss(env, 10, 1, 2, 0.7, unused), l1);
    EXPECT_NE(env_nonnegativity_loss(env, 10, 2, 1, 0.7, unused), l1);
}

}  // namespace
}  // namespace lumigauss
