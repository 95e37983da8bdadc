#pragma once
// The surfels as the 3D Gaussians of the Inria 3DGS PLY, the form every baked export writes (ply-3dgs,
// compressed PLY, glTF): the position, three log scales (the surfel's two, and a thin third along its normal
// standing for the 2D disk), the unit quaternion, the opacity logit and the view-dependent SH of
// export/two_sided_sh.h.
#include <vector>

#include "lumigauss/math/vec.h"
#include "lumigauss/model/surfel_model.h"

namespace lumigauss {

inline constexpr float kThinScale = 1e-6f;           // the third (normal-direction) scale, linear
inline constexpr float kThinLogScale = -13.815511f;  // log(1e-6)

struct GaussianSplat {
    Vec3f position;
    Vec3f log_scale;
    Vec4f rotation;           // w x y z (unit length from gaussian_splats; any length elsewhere)
    float opacity = 0;        // logit
    Vec3f dc;                 // f_dc_0..2
    std::vector<float> rest;  // f_rest_*, channel-major: 3 x ((degree + 1)^2 - 1)
};

// One splat per surfel, in the model's order. `view_sh`: view_sh_coefficients(sh_degree) x 3 per surfel,
// coefficient-major (two_sided_view_sh). Throws Error when the degree is not 0..3 or the size does not match.
std::vector<GaussianSplat> gaussian_splats(const SurfelModel& model, const std::vector<float>& view_sh,
                                           int sh_degree);

}  // namespace lumigauss
