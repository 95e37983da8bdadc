#pragma once
// Stores that go past the caches (internal to the CPU backend), for buffers written in one phase and read
// in a later one: an ordinary store first fetches the line it writes into from memory, which for buffers
// of tens of MiB is as much traffic again as the writes themselves. Whole cache lines should be written
// (the processor combines the 16-byte pieces); a partly written line costs more than an ordinary store.
// The writing thread must end with stream_fence() before another thread reads what it wrote.
#include <cstddef>
#include <cstring>
#include <type_traits>
#if defined(__x86_64__)
#include <emmintrin.h>
#endif

namespace lumigauss::cpu {

inline constexpr std::size_t kCacheLineBytes = 64;

// *dst = src, past the caches: sizeof(T) a multiple of 16 bytes, dst aligned to 16 bytes.
template <typename T>
inline void stream_store(T* dst, const T& src) {
    static_assert(std::is_trivially_copyable_v<T> && sizeof(T) % 16 == 0);
#if defined(__x86_64__)
    for (std::size_t b = 0; b < sizeof(T); b += 16) {
        __m128i part;
        std::memcpy(&part, reinterpret_cast<const char*>(&src) + b, 16);
        _mm_stream_si128(reinterpret_cast<__m128i*>(reinterpret_cast<char*>(dst) + b), part);
    }
#else
    std::memcpy(dst, &src, sizeof(T));
#endif
}

// Orders this thread's streamed stores before its later ones (and so before any synchronisation that
// publishes them).
inline void stream_fence() {
#if defined(__x86_64__)
    _mm_sfence();
#endif
}

}  // namespace lumigauss::cpu
