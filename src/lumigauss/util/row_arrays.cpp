#include "lumigauss/util/row_arrays.h"

#include <algorithm>

#include "lumigauss/util/error.h"

namespace lumigauss {

namespace {

std::size_t row_count(const std::vector<float>& data, int width) {
    return data.size() / static_cast<std::size_t>(width);
}

}  // namespace

void keep_rows(std::vector<float>& data, int width, std::span<const std::uint8_t> keep) {
    const auto w = static_cast<std::size_t>(width);
    if (keep.size() != row_count(data, width)) throw Error("keep_rows: mask size differs from the row count");
    std::size_t dst = 0;
    for (std::size_t r = 0; r < keep.size(); ++r) {
        if (!keep[r]) continue;
        if (dst != r)
            std::copy_n(data.begin() + static_cast<std::ptrdiff_t>(r * w), w,
                        data.begin() + static_cast<std::ptrdiff_t>(dst * w));
        ++dst;
    }
    data.resize(dst * w);
}

void append_copies_of_rows(std::vector<float>& data, int width, std::span<const std::size_t> rows) {
    const auto w = static_cast<std::size_t>(width);
    const std::size_t n = row_count(data, width);
    // Check every index first, so a bad one leaves the array untouched.
    for (std::size_t r : rows)
        if (r >= n) throw Error("duplicate_rows: row index out of range");
    // Reserve, then read by index: the source rows live in the vector being grown.
    data.reserve(data.size() + rows.size() * w);
    for (std::size_t r : rows)
        for (std::size_t i = 0; i < w; ++i) data.push_back(data[r * w + i]);
}

}  // namespace lumigauss
