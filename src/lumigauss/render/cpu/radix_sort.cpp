#include "lumigauss/render/cpu/radix_sort.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cassert>

namespace lumigauss {
namespace {

constexpr int kDigitBits = 11, kBuckets = 1 << kDigitBits;
constexpr std::size_t kMinChunk = 16384, kMaxChunks = 32;

}  // namespace

void radix_sort_pairs(std::vector<std::uint32_t>& keys, std::vector<std::uint32_t>& values,
                      RadixSortScratch& scratch) {
    assert(keys.size() == values.size());
    const std::size_t n = keys.size();
    if (n < 2) return;
    const std::size_t chunk = std::max(kMinChunk, (n + kMaxChunks - 1) / kMaxChunks);
    const std::size_t num_chunks = (n + chunk - 1) / chunk;
    scratch.keys.resize(n);
    scratch.values.resize(n);
    std::vector<std::uint32_t>& counts = scratch.counts;  // [chunk][bucket]
    for (int shift = 0; shift < 32; shift += kDigitBits) {
        const auto digit = [shift](std::uint32_t key) { return (key >> shift) & (kBuckets - 1); };
        counts.assign(num_chunks * kBuckets, 0);
        tbb::parallel_for(std::size_t(0), num_chunks, [&](std::size_t c) {
            std::uint32_t* count = &counts[c * kBuckets];
            for (std::size_t i = c * chunk; i < std::min(n, (c + 1) * chunk); ++i) ++count[digit(keys[i])];
        });
        // Bucket by bucket, chunk by chunk: where each chunk's keys of each digit go.
        std::uint32_t next = 0;
        bool one_bucket = false;
        for (int b = 0; b < kBuckets; ++b) {
            std::uint32_t total = 0;
            for (std::size_t c = 0; c < num_chunks; ++c) {
                const std::uint32_t count = counts[c * kBuckets + std::size_t(b)];
                counts[c * kBuckets + std::size_t(b)] = next + total;
                total += count;
            }
            one_bucket = one_bucket || total == n;
            next += total;
        }
        if (one_bucket) continue;  // this digit orders nothing
        tbb::parallel_for(std::size_t(0), num_chunks, [&](std::size_t c) {
            std::uint32_t* cursor = &counts[c * kBuckets];
            for (std::size_t i = c * chunk; i < std::min(n, (c + 1) * chunk); ++i) {
                const std::uint32_t to = cursor[digit(keys[i])]++;
                scratch.keys[to] = keys[i];
                scratch.values[to] = values[i];
            }
        });
        keys.swap(scratch.keys);
        values.swap(scratch.values);
    }
}

}  // namespace lumigauss
