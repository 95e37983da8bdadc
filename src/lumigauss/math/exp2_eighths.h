#pragma once
// 2^(n/8) for integer n, the table step of the rasterizer's float exp (render/surfel_kernel.h,
// kernel_exp): its range reduction works in eighths of ln 2, x = n ln2 / 8 + r with n = 8k + j, 0 <= j < 8,
// and 2^(n/8) = 2^(j/8) 2^k is a table entry with its exponent raised by k. n arrives in the low bits of
// a float: `shifted` = n + kExpRoundMagic. (The CPU packs have their own overload: render/cpu/lane_pack.h.)
#include <cstdint>

#include "lumigauss/math/hd.h"

namespace lumigauss {

inline constexpr float kExpRoundMagic = 12582912.0f;            // 1.5 * 2^23: adding it rounds to an integer
inline constexpr std::int32_t kExpRoundMagicBits = 0x4B400000;  // its bits: n + magic has bits magic + n
// 2^(j/8), rounded to float, for 0 <= j < 8.
LG_HD constexpr float exp2_eighth(int j) {
    switch (j) {
        case 0:
            return 1.0f;
        case 1:
            return 1.0905077326652577f;
        case 2:
            return 1.189207115002721f;
        case 3:
            return 1.2968395546510096f;
        case 4:
            return 1.4142135623730951f;
        case 5:
            return 1.5422108254079407f;
        case 6:
            return 1.681792830507429f;
        default:
            return 1.8340080864093424f;
    }
}
// The same as a table, for the CPU.
inline constexpr float kExp2Eighths[8] = {exp2_eighth(0), exp2_eighth(1), exp2_eighth(2), exp2_eighth(3),
                                          exp2_eighth(4), exp2_eighth(5), exp2_eighth(6), exp2_eighth(7)};

// For -1008 <= n <= 0 (k >= -126: the result stays a normal float).
LG_HD_INLINE float exp2_eighths(float shifted) {
    std::int32_t n;
    __builtin_memcpy(&n, &shifted, sizeof(float));
    n -= kExpRoundMagicBits;
    std::int32_t bits;
#if defined(__CUDA_ARCH__)
    // A GPU thread picks the entry by selects: a table in memory would be a load per call, serialised
    // across a warp whose threads want different entries.
    const int j = n & 7;
    const float lo =
        (j & 2) ? ((j & 1) ? exp2_eighth(3) : exp2_eighth(2)) : ((j & 1) ? exp2_eighth(1) : exp2_eighth(0));
    const float hi =
        (j & 2) ? ((j & 1) ? exp2_eighth(7) : exp2_eighth(6)) : ((j & 1) ? exp2_eighth(5) : exp2_eighth(4));
    const float entry = (j & 4) ? hi : lo;
    __builtin_memcpy(&bits, &entry, sizeof(float));
#else
    __builtin_memcpy(&bits, &kExp2Eighths[n & 7], sizeof(float));
#endif
    bits += (n >> 3) * (std::int32_t(1) << 23);  // k onto the exponent
    float scale;
    __builtin_memcpy(&scale, &bits, sizeof(float));
    return scale;
}

}  // namespace lumigauss
