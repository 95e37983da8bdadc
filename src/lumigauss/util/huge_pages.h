#pragma once
// Large scratch buffers on transparent huge pages. The rasterizer's per-surfel and per-entry buffers run to
// hundreds of MiB at a million surfels, and a call that touches them first (the first of a run, or after
// the surfel count grew) pays a page fault for every page. With huge pages that call measured faster on
// two threads (1M surfels at 320x240, forward + backward: 331-342 ms against 450-486 ms on 4 KiB pages),
// not on one (too noisy to tell). Calls that reuse the buffers, the steady state, measured the same either
// way (1 thread 328-363 / 288-378 ms, 2 threads 160-184 / 157-188 ms): the random accesses are not
// TLB-bound. Debian's default ("madvise" mode) gives huge pages only to memory that asks for them.
#include <cstddef>
#include <vector>

namespace lumigauss {

// Asks for huge pages on the whole 2 MiB pages inside [data, data + bytes), for ranges of 4 MiB or more.
// Only memory not yet touched gets them. Does nothing where the system has no such advice.
void advise_huge_pages(void* data, std::size_t bytes);

// v.resize(n) for a buffer that is entirely overwritten after it: when it must grow, its old contents are
// dropped instead of copied, and the new memory is advised for huge pages before anything touches it.
template <typename T, typename A>
void resize_for_overwrite(std::vector<T, A>& v, std::size_t n) {
    if (n > v.capacity()) {
        std::vector<T, A>().swap(v);
        v.reserve(n);
        advise_huge_pages(v.data(), n * sizeof(T));
    }
    v.resize(n);
}

}  // namespace lumigauss
