// resize_for_overwrite: the buffers the rasterizer reuses from call to call, grown on huge pages.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "lumigauss/util/huge_pages.h"

namespace lumigauss {
namespace {

TEST(HugePages, ResizeForOverwriteGivesTheSizeAndKeepsTheBufferWhenItFits) {
    std::vector<float> v;
    resize_for_overwrite(v, 3 << 20);  // 12 MiB: advised for huge pages
    ASSERT_EQ(v.size(), std::size_t(3) << 20);
    for (std::size_t i = 0; i < v.size(); i += 1021) v[i] = float(i);  // every page is usable
    EXPECT_EQ(v[1021 * 7], float(1021 * 7));
    const float* data = v.data();
    resize_for_overwrite(v, 1000);  // shrinking or regrowing within the capacity keeps the memory
    EXPECT_EQ(v.size(), 1000u);
    resize_for_overwrite(v, 2 << 20);
    EXPECT_EQ(v.data(), data);
    EXPECT_EQ(v.size(), std::size_t(2) << 20);
    resize_for_overwrite(v, 4 << 20);  // growing past it: new memory, the requested size
    EXPECT_EQ(v.size(), std::size_t(4) << 20);
    EXPECT_GE(v.capacity(), v.size());
}

TEST(HugePages, AdviceOnSmallUnalignedOrNoMemoryIsHarmless) {
    advise_huge_pages(nullptr, 0);
    advise_huge_pages(nullptr, std::size_t(8) << 20);
    std::vector<std::uint8_t> small(1000, 7);
    advise_huge_pages(small.data() + 1, small.size() - 1);
    EXPECT_EQ(small[999], 7);
    std::vector<std::uint8_t> large(std::size_t(5) << 20, 3);  // touched already: keeps its pages
    advise_huge_pages(large.data() + 17, large.size() - 17);
    EXPECT_EQ(large[large.size() - 1], 3);
}

}  // namespace
}  // namespace lumigauss
