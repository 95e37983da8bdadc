#pragma once
// How much of a view's sky (gt/mask exactly 0) a render covers with surfels: seen from a new viewpoint,
// surfels there are floaters. Two measures, because they catch different failures: the share of sky pixels
// the render covers (alpha > 0.5: surfels painting the sky), and the mean alpha over the sky (a faint veil,
// such as one large surfel just above the prune threshold hanging in front of the camera, that never reaches
// 0.5).
#include <cstddef>
#include <span>

#include "lumigauss/io/image.h"

namespace lumigauss {

struct SkyCoverage {
    std::size_t pixels = 0;  // sky pixels (mask exactly 0)
    double covered = 0;      // share of them with alpha > 0.5
    double mean_alpha = 0;   // mean alpha over them
};

// `mask`: the evaluation mask (1 channel, 0 = sky); `alpha`: the render's alpha, one value per pixel of it.
SkyCoverage sky_coverage(const Image& mask, std::span<const float> alpha);

}  // namespace lumigauss
