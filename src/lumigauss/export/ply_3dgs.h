#pragma once
// The standard 3D Gaussian Splatting PLY (graphdeco-inria/gaussian-splatting `save_ply`), which splat
// viewers and engine plug-ins open, with colours baked under one lighting. One vertex per surfel, binary
// little-endian float32, in this order:
//   x y z             position
//   nx ny nz          the surfel's unit +normal (3DGS writes zeros; readers ignore them)
//   f_dc_0..2         the DC view-dependent SH coefficient per channel (colour = 0.5 + Y00 f_dc + ...)
//   f_rest_*          3 * ((degree + 1)^2 - 1) coefficients (0, 9, 24 or 45), channel-major as 3DGS stores
//                     them: f_rest_{c * (K - 1) + k - 1} is coefficient k of channel c
//   opacity           the model's opacity logit, copied
//   scale_0 scale_1   the surfel's two log scales, copied
//   scale_2           kThinLogScale = log(1e-6): a flat Gaussian standing for the 2D surfel
//   rot_0..3          the normalised quaternion, w first
// The coefficients are export/two_sided_sh.h's: each side of a surfel shows its own baked colour. The
// project's own 2DGS reader (model/splat_ply.h: load_2dgs_ply) reads this file too (it ignores scale_2 and
// the normals).
#include <string>
#include <vector>

#include "lumigauss/export/gaussian_splats.h"
#include "lumigauss/model/surfel_model.h"

namespace lumigauss {

// The property names above for an SH degree 0..3, in order.
std::vector<std::string> ply_3dgs_property_names(int sh_degree);

// Writes the file atomically. `view_sh`: view_sh_coefficients(sh_degree) x 3 per surfel, coefficient-major
// (two_sided_view_sh). Throws Error naming the file on a size mismatch or I/O failure.
void write_3dgs_ply(const std::string& path, const SurfelModel& model, const std::vector<float>& view_sh,
                    int sh_degree);

}  // namespace lumigauss
