#pragma once
// Several values as one: the lane types of the CPU backend.
//
// Pack<T, N> wraps a GCC/Clang vector of N floats or doubles with ordinary arithmetic, so that the
// per-pixel and per-surfel formulas written once for a lane type (math/lanes.h) also run on N values at a
// time: comparisons give a mask (LaneInt of all-ones or zero lanes), lane_select picks per lane. The tile
// kernels use eight pixels (Pack8<float>; Pack8<double> for the double-precision reference path), the
// projection four surfels in double (Pack4d: GCC 12 turns eight-double comparisons into scalar code in
// per-instruction-set clones, four-double ones into vector instructions). Nothing here is x86-specific;
// each per-instruction-set clone (multiversion.h) compiles these operations to its own vector width.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>

#include "lumigauss/math/exp2_eighths.h"
#include "lumigauss/math/lanes.h"
#include "lumigauss/render/cpu/streaming_store.h"
#include "lumigauss/render/cpu/vector_shuffle.h"

namespace lumigauss::cpu {

inline constexpr int kLanes = 8;  // pixels per pack in the tile kernels

// The vector types of N lanes of T, and the integers of T's width.
template <typename T, int N>
struct LaneVectors;
template <int N>
struct LaneVectors<float, N> {
    using Int = std::int32_t;
    typedef float F __attribute__((vector_size(N * sizeof(float))));
    typedef std::int32_t I __attribute__((vector_size(N * sizeof(std::int32_t))));
};
template <int N>
struct LaneVectors<double, N> {
    using Int = std::int64_t;
    typedef double F __attribute__((vector_size(N * sizeof(double))));
    typedef std::int64_t I __attribute__((vector_size(N * sizeof(std::int64_t))));
};

// Per-lane integers of T's width: lane masks (all bits set = true) and per-pixel indices.
template <typename T, int N>
struct LaneInt {
    using I = typename LaneVectors<T, N>::Int;
    using V = typename LaneVectors<T, N>::I;
    V v;
    LaneInt() = default;
    constexpr LaneInt(V x) : v(x) {}
    LaneInt(I s) : v(LG_SHUFFLE(V{s}, V{})) {}  // broadcast (see Pack)
    I operator[](int i) const { return v[i]; }
    friend LaneInt operator&(LaneInt a, LaneInt b) { return {a.v & b.v}; }
    friend LaneInt operator|(LaneInt a, LaneInt b) { return {a.v | b.v}; }
    friend LaneInt operator==(LaneInt a, LaneInt b) { return {a.v == b.v}; }
    friend LaneInt operator<=(LaneInt a, LaneInt b) { return {a.v <= b.v}; }
    friend LaneInt operator>=(LaneInt a, LaneInt b) { return {a.v >= b.v}; }
    friend LaneInt operator+(LaneInt a, LaneInt b) { return {a.v + b.v}; }
};

template <typename T, int N>
struct Pack {
    using Scalar = T;
    using Index = LaneInt<T, N>;
    using V = typename LaneVectors<T, N>::F;
    static constexpr int kSize = N;
    V v;
    Pack() = default;
    constexpr Pack(V x) : v(x) {}
    // Broadcast, spelled as lane 0 shuffled into every lane: GCC 12 compiles that to one broadcast, while
    // `s - V{}` or a lane-by-lane initialiser in a constructor become chains of inserts, and `V{} + s`
    // costs an add (0 + -0 is +0).
    Pack(T s) : v(LG_SHUFFLE(V{s}, typename Index::V{})) {}  // implicit: formulas mix packs, scalars
    template <typename U>
    requires std::is_arithmetic_v<U>
    explicit Pack(U s) : Pack(static_cast<T>(s)) {}  // L(constant), as T(constant) for a scalar
    T operator[](int i) const { return v[i]; }

    friend Pack operator+(Pack a, Pack b) { return {a.v + b.v}; }
    friend Pack operator-(Pack a, Pack b) { return {a.v - b.v}; }
    friend Pack operator*(Pack a, Pack b) { return {a.v * b.v}; }
    friend Pack operator/(Pack a, Pack b) { return {a.v / b.v}; }
    friend Pack operator-(Pack a) { return {-a.v}; }
    Pack& operator+=(Pack b) { return v += b.v, *this; }
    Pack& operator-=(Pack b) { return v -= b.v, *this; }
    Pack& operator*=(Pack b) { return v *= b.v, *this; }

    friend Index operator<(Pack a, Pack b) { return {a.v < b.v}; }
    friend Index operator<=(Pack a, Pack b) { return {a.v <= b.v}; }
    friend Index operator>(Pack a, Pack b) { return {a.v > b.v}; }
    friend Index operator>=(Pack a, Pack b) { return {a.v >= b.v}; }
    friend Index operator==(Pack a, Pack b) { return {a.v == b.v}; }
    friend Index operator!=(Pack a, Pack b) { return {a.v != b.v}; }
};

// The tile kernels' names: eight lanes.
template <typename T>
using Pack8 = Pack<T, kLanes>;
template <typename T>
using Int8 = LaneInt<T, kLanes>;
template <typename T>
using Mask8 = Int8<T>;
using Pack4d = Pack<double, 4>;

template <typename T, int N>
inline Pack<T, N> lane_select(LaneInt<T, N> m, Pack<T, N> a, Pack<T, N> b) {
    return {m.v ? a.v : b.v};
}
template <typename T, int N>
inline LaneInt<T, N> lane_select(LaneInt<T, N> m, LaneInt<T, N> a, LaneInt<T, N> b) {
    return {m.v ? a.v : b.v};
}
template <typename T, int N>
inline LaneInt<T, N> lane_not(LaneInt<T, N> m) {
    return {~m.v};
}
// Square root per lane (math/lanes.h has the scalar ones). Without errno (-fno-math-errno), this compiles
// to the vector instruction.
template <typename T, int N>
inline Pack<T, N> lane_sqrt(Pack<T, N> x) {
    Pack<T, N> r;
    for (int i = 0; i < N; ++i) r.v[i] = std::sqrt(x.v[i]);
    return r;
}

// Whether any lane of each of two masks is set: bit 0 for a, bit 1 for b.
template <typename T>
inline unsigned any_of_each(Mask8<T> a, Mask8<T> b) {
    // Folded in halves by shuffles (as 64-bit words through general registers, the blending loop's
    // copy took four more instructions).
    using V = typename Int8<T>::V;
    V bits = (a.v & 1) | (b.v & 2);
    bits |= LG_SHUFFLE(bits, V{4, 5, 6, 7, 0, 1, 2, 3});
    bits |= LG_SHUFFLE(bits, V{2, 3, 0, 1, 2, 3, 0, 1});
    bits |= LG_SHUFFLE(bits, V{1, 0, 1, 0, 1, 0, 1, 0});
    return unsigned(bits[0]);
}

// 2^(n/8) per lane from n + kExpRoundMagic (kernel_exp; the scalar exp2_eighths in math/exp2_eighths.h): one
// permutation of the eight-entry table (the index is taken modulo 8), the exponent raised by n >> 3.
inline Pack8<float> exp2_eighths(Pack8<float> shifted) {
    using IV = Int8<float>::V;
    const IV n = (IV)shifted.v - kExpRoundMagicBits;  // GCC vector cast: the same bits reinterpreted
    const Pack8<float>::V table = {kExp2Eighths[0], kExp2Eighths[1], kExp2Eighths[2], kExp2Eighths[3],
                                   kExp2Eighths[4], kExp2Eighths[5], kExp2Eighths[6], kExp2Eighths[7]};
    const IV bits = (IV)LG_SHUFFLE(table, n) + (n >> 3) * (1 << 23);
    return {(Pack8<float>::V)bits};
}

// lane_split_exponent (math/lanes.h) per lane, from the bits: the exponent field, and the mantissa with the
// exponent of 1/2.
template <typename T, int N>
inline Pack<T, N> lane_split_exponent(Pack<T, N> x, Pack<T, N>& m) {
    using IV = typename LaneInt<T, N>::V;
    using I = typename LaneInt<T, N>::I;
    constexpr int kMantissaBits = std::numeric_limits<T>::digits - 1;
    constexpr I kMantissa = (I(1) << kMantissaBits) - 1;
    constexpr I kHalfExponent = I(std::numeric_limits<T>::max_exponent - 2) << kMantissaBits;  // of 1/2
    const IV bits = (IV)x.v;  // GCC vector cast: the same bits reinterpreted
    const Pack<T, N> mantissa{(typename Pack<T, N>::V)((bits & kMantissa) | kHalfExponent)};  // [1/2, 1)
    const LaneInt<T, N> e{(bits >> kMantissaBits) - (std::numeric_limits<T>::max_exponent - 2)};
    const LaneInt<T, N> low = mantissa < Pack<T, N>(T(kSplitMantissaMin));
    m = lane_select(low, mantissa + mantissa, mantissa);
    return Pack<T, N>{__builtin_convertvector((e.v + low.v), typename Pack<T, N>::V)};  // a true mask is -1
}

// exp per lane in double (the reference path only).
inline Pack8<double> lane_exp(Pack8<double> x) {
    Pack8<double> r;
    for (int i = 0; i < kLanes; ++i) r.v[i] = std::exp(x.v[i]);
    return r;
}

// Lane offsets in a block of 4 x 2 pixels: lane i is pixel (i % 4, i / 4) of the block.
template <typename T>
inline Int8<T> block_lane_x() {
    return {typename Int8<T>::V{0, 1, 2, 3, 0, 1, 2, 3}};
}
template <typename T>
inline Int8<T> block_lane_y() {
    return {typename Int8<T>::V{0, 0, 0, 0, 1, 1, 1, 1}};
}
// Pixel centres (x + 0.5) of integer pixel indices.
template <typename T>
inline Pack8<T> pixel_centres(Int8<T> x) {
    return Pack8<T>{__builtin_convertvector(x.v, typename Pack8<T>::V)} + Pack8<T>(T(0.5));
}

// The 8x8 matrix of eight packs (pack r = row r) transposed in place: three levels of two-source shuffles.
template <typename T>
inline void transpose_packs(Pack8<T> (&m)[kLanes]) {
    using IV = typename Int8<T>::V;
    const auto mix = [](Pack8<T> a, Pack8<T> b, IV order) {
        return Pack8<T>{LG_SHUFFLE(a.v, b.v, order)};
    };
    const IV lo1{0, 8, 1, 9, 4, 12, 5, 13}, hi1{2, 10, 3, 11, 6, 14, 7, 15};  // pairs of rows interleaved
    const IV lo2{0, 1, 8, 9, 4, 5, 12, 13}, hi2{2, 3, 10, 11, 6, 7, 14, 15};  // then pairs of pairs
    const IV lo3{0, 1, 2, 3, 8, 9, 10, 11}, hi3{4, 5, 6, 7, 12, 13, 14, 15};  // then halves
    Pack8<T> t[kLanes], u[kLanes];
    for (int p = 0; p < 4; ++p) {
        t[2 * p] = mix(m[2 * p], m[2 * p + 1], lo1);
        t[2 * p + 1] = mix(m[2 * p], m[2 * p + 1], hi1);
    }
    for (int q = 0; q < 2; ++q) {
        u[4 * q] = mix(t[4 * q], t[4 * q + 2], lo2);
        u[4 * q + 1] = mix(t[4 * q], t[4 * q + 2], hi2);
        u[4 * q + 2] = mix(t[4 * q + 1], t[4 * q + 3], lo2);
        u[4 * q + 3] = mix(t[4 * q + 1], t[4 * q + 3], hi2);
    }
    for (int k = 0; k < 4; ++k) {
        m[k] = mix(u[k], u[4 + k], lo3);
        m[4 + k] = mix(u[k], u[4 + k], hi3);
    }
}

// Sums of the lanes of eight packs: lane j of the result is the sum of the lanes of q[j]. A transpose-add
// tree (three levels of two-source shuffles), far cheaper than eight separate horizontal sums.
template <typename T>
inline Pack8<T> lane_sums(const Pack8<T>* q) {
    using IV = typename Int8<T>::V;
    const auto fold = [](Pack8<T> a, Pack8<T> b, IV lo, IV hi) {
        return Pack8<T>{LG_SHUFFLE(a.v, b.v, lo) + LG_SHUFFLE(a.v, b.v, hi)};
    };
    // Level 1: lanes two apart, a's and b's interleaved. These are the unpack-low / unpack-high patterns,
    // one in-lane instruction each with AVX2 too (the neighbour pairs {0, 8, 2, 10, ...} took a permute
    // and a blend each there).
    const IV l1a{0, 8, 1, 9, 4, 12, 5, 13}, l1b{2, 10, 3, 11, 6, 14, 7, 15};
    const Pack8<T> s01 = fold(q[0], q[1], l1a, l1b), s23 = fold(q[2], q[3], l1a, l1b);
    const Pack8<T> s45 = fold(q[4], q[5], l1a, l1b), s67 = fold(q[6], q[7], l1a, l1b);
    // Level 2: quarters. s01 = [a02 b02 a13 b13 a46 b46 a57 b57] -> [a0-3 b0-3 c0-3 d0-3 a4-7 b4-7 ...].
    const IV l2a{0, 1, 8, 9, 4, 5, 12, 13}, l2b{2, 3, 10, 11, 6, 7, 14, 15};
    const Pack8<T> t0 = fold(s01, s23, l2a, l2b), t1 = fold(s45, s67, l2a, l2b);
    // Level 3: halves.
    const IV l3a{0, 1, 2, 3, 8, 9, 10, 11}, l3b{4, 5, 6, 7, 12, 13, 14, 15};
    return fold(t0, t1, l3a, l3b);
}

template <typename T>
inline Pack8<T> load_pack(const T* p) {
    Pack8<T> r;
    std::memcpy(&r.v, p, sizeof(r.v));
    return r;
}
// Eight per-lane integers of T's width (Int8<T>::I), as load_pack reads eight values.
template <typename T>
inline Int8<T> load_lanes(const typename Int8<T>::I* p) {
    Int8<T> r;
    std::memcpy(&r.v, p, sizeof(r.v));
    return r;
}
template <typename T>
inline void store_pack(T* p, Pack8<T> x) {
    std::memcpy(p, &x.v, sizeof(x.v));
}
// store_pack past the caches (streaming_store.h); p aligned to 16 bytes.
template <typename T>
inline void stream_pack(T* p, Pack8<T> x) {
    stream_store(reinterpret_cast<typename Pack8<T>::V*>(p), x.v);
}

}  // namespace lumigauss::cpu
