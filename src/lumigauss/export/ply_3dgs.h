#pragma once
// The standard 3D Gaussian Splatting PLY (graphdeco-inria/gaussian-splatting `save_ply`), which splat
// viewers and engine plug-ins open, with colours baked under one lighting (baked_colours.h). One vertex per
// surfel, binary little-endian float32, in this order (62 properties):
//   x y z             position
//   nx ny nz          the surfel's unit +normal (3DGS writes zeros; readers ignore them)
//   f_dc_0..2         (rgb - 0.5) / 0.28209479, rgb the baked colour in [0, 1]
//   f_rest_0..44      0 (degree-3 layout, no view dependence)
//   opacity           the model's opacity logit, copied
//   scale_0 scale_1   the surfel's two log scales, copied
//   scale_2           kThinLogScale = log(1e-6): a flat Gaussian standing for the 2D surfel
//   rot_0..3          the normalised quaternion, w first
// The project's own 2DGS reader (model/splat_ply.h: load_2dgs_ply) reads this file too (it ignores scale_2
// and the normals), which is how the tests render it back.
#include <string>
#include <vector>

#include "lumigauss/model/surfel_model.h"

namespace lumigauss {

inline constexpr float kThinScale = 1e-6f;           // the third (normal-direction) scale, linear
inline constexpr float kThinLogScale = -13.815511f;  // log(1e-6)
inline constexpr int kPly3dgsRestCount = 45;         // f_rest_0..44 (SH degree 3, all zero)

// The 62 property names above, in order.
std::vector<std::string> ply_3dgs_property_names();

// Writes the file atomically. `colours`: 3 per surfel in [0, 1] (bake_surfel_colours). Throws Error naming
// the file on a size mismatch or I/O failure.
void write_3dgs_ply(const std::string& path, const SurfelModel& model, const std::vector<float>& colours);

}  // namespace lumigauss
