#pragma once
// Deterministic row parallelism for the image losses: rows run in parallel, and per-row partial sums are
// added in row order afterwards, so results do not depend on how TBB splits the work.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <vector>

namespace lumigauss::train_detail {

template <typename F>
void for_each_row(int height, F&& f) {
    tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y < r.end(); ++y) f(y);
    });
}

template <typename T>
T sum_in_order(const std::vector<T>& parts) {
    T s = 0;
    for (T v : parts) s += v;
    return s;
}

}  // namespace lumigauss::train_detail
