// The CPU backend's lane helpers against plain loops: the transpose-add tree of lane_sums and the 8x8
// transpose (their shuffle patterns are easy to get subtly wrong: a lane summed twice or moved to the
// wrong place, another never) and the whole-pack loads.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>

#include "lumigauss/render/cpu/lane_pack.h"
#include "lumigauss/render/surfel_kernel.h"

namespace lumigauss::cpu {
namespace {

template <typename T>
void check_lane_sums() {
    std::mt19937 rng(7);
    // Powers of two of distinct sizes: every lane of every pack has its own bit, so a lane counted twice
    // or missed changes the sum, and the float sums are exact.
    std::uniform_int_distribution<int> coin(0, 1);
    for (int trial = 0; trial < 20; ++trial) {
        Pack8<T> q[kLanes];
        T expected[kLanes] = {};
        for (int j = 0; j < kLanes; ++j)
            for (int i = 0; i < kLanes; ++i) {
                const T value = T(coin(rng) ? 1 : -1) * T(std::uint64_t(1) << i) * T(1 + j);
                q[j].v[i] = value;
                expected[j] += value;
            }
        const Pack8<T> sums = lane_sums(q);
        for (int j = 0; j < kLanes; ++j) EXPECT_EQ(sums[j], expected[j]) << "pack " << j;
    }
}

TEST(LanePack, LaneSumsSumEveryLaneOfEachPackOnce) {
    check_lane_sums<float>();
    check_lane_sums<double>();
}

template <typename T>
void check_transpose() {
    Pack8<T> m[kLanes];
    for (int r = 0; r < kLanes; ++r)
        for (int c = 0; c < kLanes; ++c) m[r].v[c] = T(10 * r + c);  // every element its own value
    transpose_packs(m);
    for (int r = 0; r < kLanes; ++r)
        for (int c = 0; c < kLanes; ++c) EXPECT_EQ(m[r][c], T(10 * c + r)) << "row " << r << ", column " << c;
}

TEST(LanePack, TransposePacksSwapsRowsAndColumns) {
    check_transpose<float>();
    check_transpose<double>();
}

TEST(LanePack, LoadLanesReadsEightIndicesInOrder) {
    const std::int32_t narrow[kLanes] = {-1, 0, 1, 2, 3, 4, 5, 1 << 30};
    const std::int64_t wide[kLanes] = {-1, 0, 1, 2, 3, 4, 5, std::int64_t(1) << 40};
    const Int8<float> a = load_lanes<float>(narrow);
    const Int8<double> b = load_lanes<double>(wide);
    for (int i = 0; i < kLanes; ++i) {
        EXPECT_EQ(a[i], narrow[i]);
        EXPECT_EQ(b[i], wide[i]);
    }
}

// The table step of the float exp: 2^(n/8) for every n it is used for, as the nearest float (the exponent
// step is exact), from scalars and packs alike.
TEST(LanePack, Exp2EighthsIsTwoToTheNOverEightForEveryN) {
    const auto expected = [](int n) { return float(std::exp2(double(n) / 8.0)); };
    for (int n = -1008; n <= 0; ++n)
        ASSERT_EQ(lumigauss::exp2_eighths(float(n) + kExpRoundMagic), expected(n)) << n;
    for (int first = -1008; first <= 0; first += kLanes) {  // one n per lane: every table entry per pack
        Pack8<float> shifted;
        for (int l = 0; l < kLanes; ++l) shifted.v[l] = float(first + l) + kExpRoundMagic;
        const Pack8<float> packed = exp2_eighths(shifted);
        for (int l = 0; l < kLanes && first + l <= 0; ++l)
            ASSERT_EQ(packed[l], expected(first + l)) << first + l;
    }
}

// The float kernel's exp (surfel_kernel.h: at most 1.6 ulp) against the double one over its whole range, and
// on packs (the CPU tile kernels) to the bit equal to the scalar formula it is written as.
TEST(LanePack, KernelExpIsWithinTwoUlpOfExp) {
    double worst_ulps = 0;
    for (int i = 0; i <= 200000; ++i) {
        const float x = -87.0f * float(i) / 200000.0f;
        const float got = raster::kernel_exp(x);
        const double exact = std::exp(double(x));
        const double ulp = std::ldexp(1.0, std::ilogb(float(exact)) - 23);
        worst_ulps = std::max(worst_ulps, std::abs(double(got) - exact) / ulp);
        if (i % 8 == 0) {
            Pack8<float> xs;
            for (int l = 0; l < kLanes; ++l) xs.v[l] = x * float(l + 1) / 8.0f;
            const Pack8<float> packed = raster::kernel_exp(xs);
            for (int l = 0; l < kLanes; ++l) ASSERT_EQ(packed[l], raster::kernel_exp(xs[l])) << xs[l];
        }
    }
    EXPECT_LE(worst_ulps, 2.0);
    EXPECT_EQ(raster::kernel_exp(0.0f), 1.0f);
}

}  // namespace
}  // namespace lumigauss::cpu
