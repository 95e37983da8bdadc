// A surfel whose 3-sigma disk almost touches the camera plane: the dual-conic centre runs off to infinity
// there. Found in a plaza training run (a 1.2 m-deep ground surfel, iteration 11732) where it made the
// position gradient NaN. Forward and backward must stay finite for every map.
#include <gtest/gtest.h>

#include <cmath>

#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/render/raster_constants.h"

namespace lumigauss {
namespace {

Camera small_camera() {
    Camera c;
    c.width = 64, c.height = 48;
    c.fx = c.fy = 50, c.cx = 32, c.cy = 24;
    return c;
}

// One surfel whose u axis points along the viewing direction (z), at depth z with s_u just below
// z / kSigmaCutoff, so that d = c^2 s_u^2 - z^2 is a tiny negative number; plus a normal surfel behind it.
SurfelBatch<float> near_degenerate(float relative_gap) {
    SurfelBatch<float> b;
    b.channels = 3;
    b.resize(2);
    const float z = 1.2f, su = z / float(raster::kSigmaCutoff) * (1.0f - relative_gap);
    const float h = std::sqrt(0.5f);
    const float means[6] = {0.3f, 0.05f, z, 0.0f, 0.0f, 5.0f};
    const float quats[8] = {h, 0, -h, 0, 1, 0, 0, 0};  // R_y(-90 deg): u axis -> +z; identity
    const float scales[4] = {su, 0.3f, 1.0f, 1.0f};
    for (int i = 0; i < 6; ++i) b.means[std::size_t(i)] = means[i];
    for (int i = 0; i < 8; ++i) b.quats[std::size_t(i)] = quats[i];
    for (int i = 0; i < 4; ++i) b.scales[std::size_t(i)] = scales[i];
    b.opacities = {0.9f, 0.8f};
    b.colors = {0.8f, 0.5f, 0.2f, 0.1f, 0.6f, 0.9f};
    return b;
}

bool all_finite(const std::vector<float>& v) {
    for (float x : v)
        if (!std::isfinite(x)) return false;
    return true;
}

TEST(RasterDegenerate, DiskTouchingTheCameraPlaneGivesFiniteGradients) {
    const Camera cam = small_camera();
    for (float gap : {1e-3f, 1e-5f, 1e-7f, 0.0f}) {
        SCOPED_TRACE(gap);
        const SurfelBatch<float> batch = near_degenerate(gap);
        RasterState<float> state;
        const RasterImages<float> img = rasterize_forward_cpu(cam, batch, RasterSettings<float>{}, state);
        for (const auto* map : {&img.color, &img.alpha, &img.depth, &img.normal, &img.distortion})
            EXPECT_TRUE(all_finite(*map));
        // Non-zero incoming gradients on every map.
        RasterImageGrads<float> g;
        g.width = img.width, g.height = img.height, g.channels = 3;
        g.color.assign(img.color.size(), 0.1f);
        g.alpha.assign(img.alpha.size(), -0.2f);
        g.depth.assign(img.depth.size(), 0.05f);
        g.normal.assign(img.normal.size(), 0.3f);
        g.distortion.assign(img.distortion.size(), 1.0f);
        const SurfelGrads<float> sg = rasterize_backward_cpu(batch, state, g);
        for (const auto* v : {&sg.means, &sg.quats, &sg.scales, &sg.opacities, &sg.colors, &sg.mean2d})
            EXPECT_TRUE(all_finite(*v));
    }
}

}  // namespace
}  // namespace lumigauss
