#pragma once
// LG_HD marks functions compiled for both the CPU and CUDA backends (pbrt-v4's PBRT_CPU_GPU idea):
// every per-surfel and per-pixel formula is written once, in a header, with this marker.
#if defined(__CUDACC__)
#define LG_HD __host__ __device__
#else
#define LG_HD
#endif
