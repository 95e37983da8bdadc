#pragma once
// Surfel models in the 2DGS PLY layout (what hbb1/2d-gaussian-splatting and gsplat's 2DGS trainer write):
//   x y z, [nx ny nz], f_dc_0..2, f_rest_0..(3*((d+1)^2-1)-1) channel-major, opacity (logit),
//   scale_0 scale_1 (logs), rot_0..3 (quaternion, w first).
#include <string>
#include <vector>

#include "lumigauss/render/raster_types.h"

namespace lumigauss {

struct ViewDependentSurfels {
    SurfelBatch<float> surfels;  // activated geometry and opacity; colours filled per view
    int sh_degree = 0;           // 0..3
    std::vector<float> sh;       // per surfel (deg+1)^2 coefficients x 3 channels, coefficient-major

    std::size_t size() const { return surfels.size(); }
};

ViewDependentSurfels load_2dgs_ply(const std::string& path);
void save_2dgs_ply(const std::string& path, const ViewDependentSurfels& model);

// Fills model.surfels.colors (3 channels) for a camera at `camera_center`: max(0, 0.5 + SH(direction)).
void colors_for_view(ViewDependentSurfels& model, const Vec3d& camera_center);

}  // namespace lumigauss
