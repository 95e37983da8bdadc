#pragma once
// Row edits of a flat array with rows of `width` floats (surfel parameters, their gradients and optimizer
// moments), so that every array of a model stays aligned when surfels are removed or copied.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace lumigauss {

void keep_rows(std::vector<float>& data, int width, std::span<const std::uint8_t> keep);
void append_copies_of_rows(std::vector<float>& data, int width, std::span<const std::size_t> rows);

}  // namespace lumigauss
