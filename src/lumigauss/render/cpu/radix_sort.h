#pragma once
// Stable sort of (key, value) pairs by a 32-bit key: least-significant-digit radix sort, 11 bits a pass,
// each pass parallel over fixed chunks with their own digit counters, so the result is the serial one
// (equal keys keep their input order) whatever the number of threads. Passes whose digit is the same for
// every key are skipped (the depths of one view often share their exponent bits).
#include <cstdint>
#include <vector>

namespace lumigauss {

struct RadixSortScratch {
    std::vector<std::uint32_t> keys, values;
    std::vector<std::uint32_t> counts;
};

// Sorts `values` by `keys` (both reordered; same length).
void radix_sort_pairs(std::vector<std::uint32_t>& keys, std::vector<std::uint32_t>& values,
                      RadixSortScratch& scratch);

}  // namespace lumigauss
