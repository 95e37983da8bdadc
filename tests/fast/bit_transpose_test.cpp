#include "lumigauss/render/cpu/bit_transpose.h"

#include <gtest/gtest.h>

#include <bit>
#include <random>

namespace lumigauss::cpu {
namespace {

TEST(BitTranspose, EveryBitMovesToItsMirrorPlace) {
    std::mt19937_64 rng(7);
    for (int trial = 0; trial < 1000; ++trial) {
        const std::uint64_t x = rng();
        const std::uint64_t y = transpose_bits_8x8(x);
        for (int r = 0; r < 8; ++r)
            for (int c = 0; c < 8; ++c)
                ASSERT_EQ(x >> (8 * r + c) & 1, y >> (8 * c + r) & 1)
                    << "x = " << x << ", row " << r << ", column " << c;
    }
    static_assert(transpose_bits_8x8(0x8040201008040201ull) == 0x8040201008040201ull);  // the diagonal stays
    static_assert(transpose_bits_8x8(0xFFull) == 0x0101010101010101ull);  // a row becomes a column
}

TEST(BitTranspose, SetBitPositionsListEachSetBitInOrder) {
    for (unsigned value = 0; value < 256; ++value) {
        const auto position = [&](int n) { return kSetBitPositions[value] >> (4 * n) & 0xfu; };
        const int count = std::popcount(value);
        unsigned rebuilt = 0;
        for (int n = 0; n < count; ++n) {
            if (n > 0) {
                EXPECT_GT(position(n), position(n - 1)) << "value " << value;
            }
            rebuilt |= 1u << position(n);
        }
        EXPECT_EQ(rebuilt, value);
        for (int n = count; n < 8; ++n) EXPECT_EQ(position(n), 0u) << "value " << value;  // the rest is zero
    }
}

}  // namespace
}  // namespace lumigauss::cpu
