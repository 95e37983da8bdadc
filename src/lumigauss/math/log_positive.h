#pragma once
// The natural logarithm of a positive normal number, per lane (math/lanes.h), in plain arithmetic: the
// same operations on every backend and lane type, so that a bound computed from it (reach_rho) is the
// same on the CPU and the GPU, and four surfels' logarithms cost one pass through packs on the CPU instead
// of a libm call per surfel. Within a few units in the last place of std::log.
#include "lumigauss/math/hd.h"
#include "lumigauss/math/lanes.h"

namespace lumigauss {

template <typename L>
LG_HD_INLINE L log_positive(L x) {
    L m;
    const L e = lane_split_exponent(x, m);  // x = m 2^e, sqrt(1/2) <= m < sqrt(2)
    // log m = 2 atanh(s) = 2 (s + s^3/3 + s^5/5 + ...) with s = (m - 1) / (m + 1), |s| <= 0.1716: the
    // terms past s^23 (double) or s^9 (float) fall below the type's rounding.
    constexpr int kTerms = sizeof(lane_scalar_t<L>) == sizeof(float) ? 5 : 12;
    const L s = (m - L(1)) / (m + L(1));
    const L z = s * s;
    L series = L(1.0 / (2 * kTerms - 1));
    for (int k = kTerms - 2; k >= 0; --k) series = series * z + L(1.0 / (2 * k + 1));
    return e * L(0.693147180559945309417232121458) + L(2) * s * series;
}

}  // namespace lumigauss
