#pragma once
// Gaussian splats in binary glTF 2.0 (.glb) with the extension KHR_gaussian_splatting (Khronos, release
// candidate of 2026; read by Babylon.js, three.js, the PlayCanvas engine, the glTF sample renderer and
// loaders.gl). One node, one mesh, one primitive of mode POINTS whose attributes, all float32, one buffer
// view each, are
//   POSITION                                  VEC3, with min and max
//   KHR_gaussian_splatting:ROTATION           VEC4, the unit quaternion in glTF order x y z w
//   KHR_gaussian_splatting:SCALE              VEC3, linear standard deviations (exp of the log scales; the
//                                             surfel's thin third axis 1e-6)
//   KHR_gaussian_splatting:OPACITY            SCALAR, sigmoid(opacity logit)
//   KHR_gaussian_splatting:SH_DEGREE_l_COEF_n VEC3 (RGB) per view-dependent coefficient, n = m + l, in the
//                                             Inria 3DGS basis and signs: colour = 0.5 + Y00 SH0 + ...
//   COLOR_0                                   VEC4 unsigned byte normalised: the DC colour made linear, and
//                                             the opacity, for viewers that draw the file as points
// and the extension object {kernel "ellipse", colorSpace "srgb_rec709_display", projection "perspective",
// sortingMethod "cameraDistance"}. The extension is listed as used, not required, so a viewer without it
// shows a point cloud. glTF is y-up: the model is handed over already turned (export/world_turn.h).
#include <string>
#include <vector>

#include "lumigauss/model/surfel_model.h"

namespace lumigauss {

// The .glb bytes of `model` with `view_sh` as in write_3dgs_ply (view_sh_coefficients(sh_degree) x 3 per
// surfel, coefficient-major). Throws Error on a size mismatch, a degree outside 0..3 or an empty model.
std::string gltf_splats_glb(const SurfelModel& model, const std::vector<float>& view_sh, int sh_degree);

// The same, written atomically to `path` (errors name the file).
void write_gltf_splats(const std::string& path, const SurfelModel& model, const std::vector<float>& view_sh,
                       int sh_degree);

}  // namespace lumigauss
