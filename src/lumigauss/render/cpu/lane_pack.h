#pragma once
// Eight pixels as one value: the lane type of the CPU backend's tile kernels.
//
// Pack8<T> wraps a GCC/Clang vector of eight floats (or doubles, for the double-precision reference path)
// with ordinary arithmetic, so the per-pixel formulas of surfel_kernel.h and pixel_blend.h, written once
// for a scalar T, also run on eight pixels at a time: comparisons give a Mask8, lane_select picks per
// lane. Nothing here is x86-specific; each per-instruction-set clone of the tile kernels (multiversion.h)
// compiles these operations to its own vector width (two SSE halves, one AVX2 or AVX-512VL register).
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace lumigauss::cpu {

inline constexpr int kLanes = 8;

// The vector types of eight lanes (GCC applies vector_size only to concrete types, hence one per scalar).
template <typename T>
struct LaneVectors;
template <>
struct LaneVectors<float> {
    using Int = std::int32_t;
    typedef float F __attribute__((vector_size(kLanes * sizeof(float))));
    typedef std::int32_t I __attribute__((vector_size(kLanes * sizeof(std::int32_t))));
};
template <>
struct LaneVectors<double> {
    using Int = std::int64_t;
    typedef double F __attribute__((vector_size(kLanes * sizeof(double))));
    typedef std::int64_t I __attribute__((vector_size(kLanes * sizeof(std::int64_t))));
};

// Per-lane integers of T's width: lane masks (all bits set = true) and per-pixel indices.
template <typename T>
struct Int8 {
    using I = typename LaneVectors<T>::Int;
    using V = typename LaneVectors<T>::I;
    V v;
    Int8() = default;
    constexpr Int8(V x) : v(x) {}
    Int8(I s) : v(__builtin_shuffle(V{s}, V{})) {}  // broadcast (see Pack8)
    I operator[](int i) const { return v[i]; }
    friend Int8 operator&(Int8 a, Int8 b) { return {a.v & b.v}; }
    friend Int8 operator|(Int8 a, Int8 b) { return {a.v | b.v}; }
    friend Int8 operator==(Int8 a, Int8 b) { return {a.v == b.v}; }
    friend Int8 operator<=(Int8 a, Int8 b) { return {a.v <= b.v}; }
    friend Int8 operator>=(Int8 a, Int8 b) { return {a.v >= b.v}; }
    friend Int8 operator+(Int8 a, Int8 b) { return {a.v + b.v}; }
};
template <typename T>
using Mask8 = Int8<T>;

template <typename T>
struct Pack8 {
    using Scalar = T;
    using Index = Int8<T>;
    using V = typename LaneVectors<T>::F;
    V v;
    Pack8() = default;
    constexpr Pack8(V x) : v(x) {}
    // Broadcast, spelled as lane 0 shuffled into every lane: GCC 12 compiles that to one broadcast, while
    // `s - V{}` or a lane-by-lane initialiser in a constructor become chains of inserts, and `V{} + s`
    // costs an add (0 + -0 is +0).
    Pack8(T s)
        : v(__builtin_shuffle(V{s}, typename Int8<T>::V{})) {}  // implicit: formulas mix packs, scalars
    template <typename U>
    requires std::is_arithmetic_v<U>
    explicit Pack8(U s) : Pack8(static_cast<T>(s)) {}  // L(constant), as T(constant) for a scalar
    T operator[](int i) const { return v[i]; }

    friend Pack8 operator+(Pack8 a, Pack8 b) { return {a.v + b.v}; }
    friend Pack8 operator-(Pack8 a, Pack8 b) { return {a.v - b.v}; }
    friend Pack8 operator*(Pack8 a, Pack8 b) { return {a.v * b.v}; }
    friend Pack8 operator/(Pack8 a, Pack8 b) { return {a.v / b.v}; }
    friend Pack8 operator-(Pack8 a) { return {-a.v}; }
    Pack8& operator+=(Pack8 b) { return v += b.v, *this; }
    Pack8& operator-=(Pack8 b) { return v -= b.v, *this; }
    Pack8& operator*=(Pack8 b) { return v *= b.v, *this; }

    friend Mask8<T> operator<(Pack8 a, Pack8 b) { return {a.v < b.v}; }
    friend Mask8<T> operator<=(Pack8 a, Pack8 b) { return {a.v <= b.v}; }
    friend Mask8<T> operator>(Pack8 a, Pack8 b) { return {a.v > b.v}; }
    friend Mask8<T> operator>=(Pack8 a, Pack8 b) { return {a.v >= b.v}; }
    friend Mask8<T> operator==(Pack8 a, Pack8 b) { return {a.v == b.v}; }
    friend Mask8<T> operator!=(Pack8 a, Pack8 b) { return {a.v != b.v}; }
};

template <typename T>
inline Pack8<T> lane_select(Mask8<T> m, Pack8<T> a, Pack8<T> b) {
    return {m.v ? a.v : b.v};
}
template <typename T>
inline Int8<T> lane_select(Mask8<T> m, Int8<T> a, Int8<T> b) {
    return {m.v ? a.v : b.v};
}

// True if any lane of the mask is set.
template <typename T>
inline bool any(Mask8<T> m) {
    std::uint64_t words[sizeof(m.v) / 8];
    std::memcpy(words, &m.v, sizeof(m.v));
    std::uint64_t bits = 0;
    for (std::uint64_t w : words) bits |= w;
    return bits != 0;
}

// Two any()s for the price of one: bit 0 is set if any lane of a is, bit 1 if any lane of b is.
template <typename T>
inline unsigned any_of_each(Mask8<T> a, Mask8<T> b) {
    const typename Int8<T>::V bits = (a.v & 1) | (b.v & 2);
    std::uint64_t words[sizeof(bits) / 8];
    std::memcpy(words, &bits, sizeof(bits));
    std::uint64_t w = 0;
    for (std::uint64_t x : words) w |= x;
    return unsigned((w | (w >> 32)) & 3);
}

// 2^k for integer-valued k (the last step of kernel_exp), through the float's exponent bits.
inline Pack8<float> exp2_integer(Pack8<float> k) {
    using IV = Int8<float>::V;
    const IV bits = (__builtin_convertvector(k.v, IV) + 127) << 23;
    return {(Pack8<float>::V)bits};  // GCC vector cast: the same bits reinterpreted
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

// Sums of the lanes of eight packs: lane j of the result is the sum of the lanes of q[j]. A transpose-add
// tree (three levels of two-source shuffles), far cheaper than eight separate horizontal sums.
template <typename T>
inline Pack8<T> lane_sums(const Pack8<T>* q) {
    using IV = typename Int8<T>::V;
    const auto fold = [](Pack8<T> a, Pack8<T> b, IV lo, IV hi) {
        return Pack8<T>{__builtin_shuffle(a.v, b.v, lo) + __builtin_shuffle(a.v, b.v, hi)};
    };
    // Level 1: pairs of neighbouring lanes; a's and b's interleaved.
    const IV l1a{0, 8, 2, 10, 4, 12, 6, 14}, l1b{1, 9, 3, 11, 5, 13, 7, 15};
    const Pack8<T> s01 = fold(q[0], q[1], l1a, l1b), s23 = fold(q[2], q[3], l1a, l1b);
    const Pack8<T> s45 = fold(q[4], q[5], l1a, l1b), s67 = fold(q[6], q[7], l1a, l1b);
    // Level 2: quarters. s01 = [a01 b01 a23 b23 a45 b45 a67 b67] -> [a0-3 b0-3 c0-3 d0-3 a4-7 b4-7 ...].
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
template <typename T>
inline void store_pack(T* p, Pack8<T> x) {
    std::memcpy(p, &x.v, sizeof(x.v));
}

}  // namespace lumigauss::cpu
