#pragma once
// The backward of model/view_shading.h's shade_surfels: from the gradient of every surfel's colour into the
// model's raw parameters (albedo, transfer, quaternion through the normal) and the photo's environment SH.
#include <span>

#include "lumigauss/model/view_shading.h"
#include "lumigauss/train/gaussian_model.h"

namespace lumigauss {

// Backward of shade_surfels: `g_colors` holds dL/dcolour, shading_channels(mode) per surfel. Adds the
// gradients of the raw albedo, of channel 0 of the used transfer sets (only in modes with shadowing) and,
// through the normal, of the raw quaternion (only in modes with the unshadowed term) into the model's
// gradient buffers; returns dL/denv. The reduction over surfels runs in fixed chunks summed in order, so
// the result does not depend on thread scheduling.
ShCoeffs<float> shade_surfels_backward(GaussianModel& model, const ShCoeffs<float>& env, ShadingMode mode,
                                       const ViewNormals& normals, std::span<const float> g_colors);

}  // namespace lumigauss
