#pragma once
// Scalar "lanes": the per-surfel and per-pixel formulas of the renderer are written once for a lane type L,
// either a scalar (float or double: references, tests, one CUDA thread) or a pack of values computed at once
// (the CPU backend's cpu::Pack: eight pixels, or four surfels in double; it brings its own overloads of
// these functions, found by argument-dependent lookup). For a pack, comparisons give a per-lane mask and
// lane_select picks per lane; for a scalar, a bool and ?:.
#include <cmath>
#include <cstdint>

#include "lumigauss/math/hd.h"

namespace lumigauss {

template <typename T>
LG_HD_INLINE T lane_select(bool m, T a, T b) {
    return m ? a : b;
}
LG_HD_INLINE bool lane_not(bool m) {
    return !m;
}
template <typename L>
using LaneMask = decltype(L{} < L{});

// The scalar type of a lane type (L itself for scalars).
template <typename L>
struct LaneScalar {
    using type = L;
};
template <typename L>
requires requires {
    typename L::Scalar;
}
struct LaneScalar<L> {
    using type = typename L::Scalar;
};
template <typename L>
using lane_scalar_t = typename LaneScalar<L>::type;

// The integer per lane (indices, counts): int for scalars, the pack's Index type for packs.
template <typename L>
struct LaneIndexOf {
    using type = std::int32_t;
};
template <typename L>
requires requires {
    typename L::Index;
}
struct LaneIndexOf<L> {
    using type = typename L::Index;
};
template <typename L>
using LaneIndex = typename LaneIndexOf<L>::type;

LG_HD_INLINE float lane_sqrt(float x) {
    return std::sqrt(x);
}
LG_HD_INLINE double lane_sqrt(double x) {
    return std::sqrt(x);
}
LG_HD_INLINE double lane_exp(double x) {
    return std::exp(x);
}

// x = m 2^e with sqrt(1/2) <= m < sqrt(2), for a positive normal x (log_positive's reduction); returns e.
// (The CPU's packs split the bits instead, with the same bound: lane_pack.h.)
inline constexpr double kSplitMantissaMin = 0.70710678118654752440;  // sqrt(1/2)
template <typename T>
LG_HD_INLINE T lane_split_exponent(T x, T& m) {
    int e;
    m = std::frexp(x, &e);  // m in [1/2, 1)
    const bool low = m < T(kSplitMantissaMin);
    m = low ? m + m : m;
    return T(low ? e - 1 : e);
}

// True where x is finite (x - x is 0 for finite x, NaN for infinities and NaN). Needs IEEE semantics
// (no -ffinite-math-only), which the project keeps.
template <typename L>
LG_HD_INLINE LaneMask<L> lane_isfinite(L x) {
    return (x - x) == L(0);
}

template <typename L>
LG_HD_INLINE L lane_min(L a, L b) {
    return lane_select(a < b, a, b);
}
template <typename L>
LG_HD_INLINE L lane_max(L a, L b) {
    return lane_select(a > b, a, b);
}
template <typename L>
LG_HD_INLINE L lane_abs(L x) {
    return lane_max(x, -x);
}

}  // namespace lumigauss
