#pragma once
// LG_HD marks functions compiled for both the CPU and CUDA backends (pbrt-v4's PBRT_CPU_GPU idea):
// every per-surfel and per-pixel formula is written once, in a header, with this marker.
#if defined(__CUDACC__)
#define LG_HD __host__ __device__
#else
#define LG_HD
#endif

// For the per-pixel kernels: inlined into every caller even in very large translation units (the CPU
// backend compiles each kernel for several instruction sets), since a call inside a pixel loop stops it
// from vectorising.
// Lambdas inside such functions need it too: the CPU backend's per-instruction-set clones rely on GCC's
// `flatten` to inline them, and once it left one out of line (compiled for baseline x86-64, called from an
// AVX2 clone with 32-byte vectors, which the two pass differently: a crash).
#if defined(__GNUC__) && !defined(__CUDACC__)
#define LG_LAMBDA_INLINE __attribute__((always_inline))
#else
#define LG_LAMBDA_INLINE
#endif
#if defined(__CUDACC__)
#define LG_HD_INLINE __host__ __device__ __forceinline__
#elif defined(__GNUC__)
#define LG_HD_INLINE __attribute__((always_inline)) inline
#else
#define LG_HD_INLINE inline
#endif
