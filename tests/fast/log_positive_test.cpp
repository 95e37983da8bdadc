#include "lumigauss/math/log_positive.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "lumigauss/render/cpu/lane_pack.h"
#include "lumigauss/render/surfel_projection.h"

namespace lumigauss {
namespace {

// Positive normal numbers over the whole exponent range, and many near 1 (where log is small).
template <typename T>
std::vector<T> test_values(std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0, 1);
    const double lo = std::log(double(std::numeric_limits<T>::min())),
                 hi = std::log(double(std::numeric_limits<T>::max()));
    std::vector<T> v{T(1),
                     T(2),
                     T(0.5),
                     std::numeric_limits<T>::min(),
                     std::numeric_limits<T>::max(),
                     T(kSplitMantissaMin),  // where the reduction's mantissa range starts
                     std::nextafter(T(kSplitMantissaMin), T(0))};
    for (int i = 0; i < 20000; ++i) v.push_back(T(std::exp(lo + (hi - lo) * unit(rng))));
    for (int i = 0; i < 20000; ++i) v.push_back(T(0.5 + 1.5 * unit(rng)));
    return v;
}

// Against std::log: a few units in the last place of the result (or of 1, where the result is near 0).
template <typename T>
void expect_close_to_std_log(int max_ulps) {
    const T eps = std::numeric_limits<T>::epsilon();
    for (T x : test_values<T>(17)) {
        const T want = std::log(x);
        const T got = log_positive(x);
        ASSERT_LE(std::abs(got - want), T(max_ulps) * eps * std::max(T(1), std::abs(want))) << "x = " << x;
    }
}

TEST(LogPositive, DoubleWithinAFewUlpsOfStdLog) {
    expect_close_to_std_log<double>(4);
}

TEST(LogPositive, FloatWithinAFewUlpsOfStdLog) {
    expect_close_to_std_log<float>(4);
}

TEST(LogPositive, KnownAnswers) {
    EXPECT_EQ(log_positive(1.0), 0.0);
    EXPECT_NEAR(log_positive(2.0), 0.693147180559945309417, 1e-16);
    EXPECT_NEAR(log_positive(255.0), 5.54126354515842759, 4e-15);
    EXPECT_NEAR(log_positive(1e-300), -690.775527898213705205, 1e-12);
}

// The CPU projection takes four surfels' logarithms at once: each lane must be the scalar result, bit for
// bit, so that a surfel's reach does not depend on its neighbours or on the backend.
TEST(LogPositive, PackLanesEqualTheScalarFunction) {
    const std::vector<double> values = test_values<double>(23);
    for (std::size_t i = 0; i + 4 <= values.size(); i += 4) {
        cpu::Pack4d x;
        for (int l = 0; l < 4; ++l) x.v[l] = values[i + std::size_t(l)];
        cpu::Pack4d m;
        const cpu::Pack4d e = lane_split_exponent(x, m);
        const cpu::Pack4d log = log_positive(x);
        for (int l = 0; l < 4; ++l) {
            double m_scalar;
            const double e_scalar = lane_split_exponent(x[l], m_scalar);
            ASSERT_EQ(e[l], e_scalar) << "x = " << x[l];
            ASSERT_EQ(m[l], m_scalar) << "x = " << x[l];
            ASSERT_EQ(log[l], log_positive(x[l])) << "x = " << x[l];
        }
    }
}

// reach_rho's bound: opacity * exp(-rho / 2) = kAlphaMin at rho just below it, for packs as for scalars.
TEST(LogPositive, ReachRhoBoundsWhereAlphaFallsBelowTheThreshold) {
    for (double opacity : {1.0, 0.99, 0.5, 0.05, 0.004, 1.0 / 255}) {
        const double rho = raster::reach_rho(opacity);
        if (opacity <= raster::kAlphaMin) {
            EXPECT_EQ(rho, -1.0);
            continue;
        }
        const double exact = 2 * std::log(opacity / raster::kAlphaMin);
        EXPECT_GE(rho, exact) << opacity;                  // never cuts off what reaches the threshold
        EXPECT_LE(rho, exact * 1.0002 + 2e-6) << opacity;  // and only by its hair of slack
        const cpu::Pack4d lanes = raster::reach_rho(cpu::Pack4d(opacity));
        for (int l = 0; l < 4; ++l) EXPECT_EQ(lanes[l], rho);
    }
}

}  // namespace
}  // namespace lumigauss
