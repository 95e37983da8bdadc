// The sky's coverage by a render (eval/sky_coverage.h): known answers for both measures.
#include <gtest/gtest.h>

#include <vector>

#include "lumigauss/eval/sky_coverage.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

Image mask_of(const std::vector<float>& values) {
    Image m(int(values.size()), 1, 1);
    m.pixels = values;
    return m;
}

TEST(EvalSkyCoverage, ShareAboveHalfAndMeanAlphaOverSkyPixelsOnly) {
    // Sky (0) at pixels 0, 1, 2 and 4; pixel 3 is scored scene (1) and pixel 5 half-masked (0.5): not sky.
    const Image mask = mask_of({0, 0, 0, 1, 0, 0.5f});
    const std::vector<float> alpha = {0.6f, 0.05f, 0.0f, 1.0f, 0.5f, 1.0f};
    const SkyCoverage s = sky_coverage(mask, alpha);
    EXPECT_EQ(s.pixels, 4u);
    EXPECT_DOUBLE_EQ(s.covered, 0.25);  // only 0.6 is above one half (0.5 is not)
    EXPECT_NEAR(s.mean_alpha, (0.6 + 0.05 + 0.0 + 0.5) / 4, 1e-7);
}

// A faint veil over the whole sky: no pixel above one half, so only the mean alpha sees it.
TEST(EvalSkyCoverage, AFaintVeilShowsInTheMeanAlphaOnly) {
    const Image mask = mask_of(std::vector<float>(100, 0.0f));
    const SkyCoverage s = sky_coverage(mask, std::vector<float>(100, 0.045f));
    EXPECT_EQ(s.covered, 0.0);
    EXPECT_NEAR(s.mean_alpha, 0.045, 1e-7);
}

TEST(EvalSkyCoverage, NoSkyAndMismatchedSizes) {
    const SkyCoverage none = sky_coverage(mask_of({1, 1}), std::vector<float>{0.9f, 0.1f});
    EXPECT_EQ(none.pixels, 0u);
    EXPECT_EQ(none.mean_alpha, 0.0);
    EXPECT_THROW(sky_coverage(mask_of({0, 0}), std::vector<float>{0.5f}), Error);
}

}  // namespace
}  // namespace lumigauss
