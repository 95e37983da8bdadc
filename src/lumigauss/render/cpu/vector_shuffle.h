#pragma once
// LG_SHUFFLE(a, mask) and LG_SHUFFLE(a, b, mask): GCC's __builtin_shuffle on vector types, with its meaning
// (lane i of the result is lane mask[i] of a, or of a then b, indices taken modulo the lane count). GCC gets
// the builtin itself, so its code is unchanged; other compilers (clang, for the libFuzzer build of
// scripts/fuzz.sh) get the same lanes from a loop: correct, not tuned.
#if defined(__GNUC__) && !defined(__clang__)
#define LG_SHUFFLE __builtin_shuffle
#else
namespace lumigauss::cpu::shuffle_detail {

template <typename V, typename M>
inline V shuffle(V a, M mask) {
    constexpr int n = int(sizeof(V) / sizeof(a[0]));
    V r{};
    for (int i = 0; i < n; ++i) r[i] = a[int(mask[i]) & (n - 1)];
    return r;
}

template <typename V, typename M>
inline V shuffle(V a, V b, M mask) {
    constexpr int n = int(sizeof(V) / sizeof(a[0]));
    V r{};
    for (int i = 0; i < n; ++i) {
        const int k = int(mask[i]) & (2 * n - 1);
        r[i] = k < n ? a[k] : b[k - n];
    }
    return r;
}

}  // namespace lumigauss::cpu::shuffle_detail
#define LG_SHUFFLE ::lumigauss::cpu::shuffle_detail::shuffle
#endif
