#pragma once
// Per-instruction-set compilation of the CPU backend's hot entry points: baseline x86-64, AVX2+FMA and
// AVX-512 versions, the best one picked at load time (GCC target_clones, an ifunc).
// ifunc-based multiversioning needs GCC on x86-64; sanitizer builds keep the baseline version only.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
#define LG_MULTIVERSION __attribute__((target_clones("default", "arch=x86-64-v3", "arch=x86-64-v4")))
#else
#define LG_MULTIVERSION
#endif
// With LG_MULTIVERSION on a function whose callees are not force-inlined: inline them all into each
// version (a call out of a clone runs the baseline version of the callee).
#if defined(__GNUC__) && !defined(__clang__)
#define LG_FLATTEN __attribute__((flatten))
#else
#define LG_FLATTEN
#endif
