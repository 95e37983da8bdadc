#pragma once
// A penalty on needle-shaped surfels (PhysGaussian's anisotropy regulariser, taken to log space).
//
// On the long schedules some surfels stretch into needles (plaza, default preset: the median ratio of the
// two tangent scales grew from 1.6 at iteration 3,000 to 6.7 at 40,000, the 99th percentile to 106). Seen
// from a training camera a needle is a thin line and costs the photos little; seen from a new viewpoint it
// is a long streak. The penalty is the mean over surfels of max(0, |log s_u - log s_v| - log max_ratio):
// zero while a surfel's ratio stays within max_ratio, then a constant pull on its log scales towards each
// other. In log space the pull does not depend on the surfel's size (PhysGaussian's s_max / s_min - r has
// a gradient 1 / s_min, which explodes on thin surfels).
// Measured on plaza's default schedule (bench/RESULTS.md, session 31): the bound holds and the scores stay,
// but the new views are not cleaner (long streaks become many short slashes: the thin surfels are mostly
// tile joints and edges, and what spoils new views is the tilt of weakly observed ones), so every preset
// leaves it off.
#include <span>

namespace lumigauss {

// `scales`: 2 linear tangent scales per surfel. Returns the penalty (unweighted mean). Adds
// weight x d(penalty)/d(scale) to `grad_scales` (same layout as `scales`).
double scale_ratio_penalty(std::span<const float> scales, double max_ratio, double weight,
                           std::span<float> grad_scales);

}  // namespace lumigauss
