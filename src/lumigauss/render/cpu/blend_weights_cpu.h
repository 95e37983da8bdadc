#pragma once
// The CPU backend's side of render/blend_weights.h: the weights of a forward pass read from its state.
#include "lumigauss/render/blend_weights.h"
#include "lumigauss/render/cpu/raster_state.h"
#include "lumigauss/render/raster_types.h"

namespace lumigauss {

// The weights of the forward pass that filled `state` (rasterize_forward_cpu on the same surfels), by the
// forward's own rules (see render_blend_weights).
BlendWeights blend_weights(const RasterState<float>& state);

}  // namespace lumigauss
