#pragma once
// The `sol-nerf` evaluation protocol: the paper's numbers on NeRF-OSR (research/lumigauss_official.md 6,
// `test_gt_env_map.py`, following SOL-NeRF). For each test photo of the config (eval/sol_nerf_config.h):
//   1. its ground-truth environment panorama (NeRF-OSR ENV_MAP_CC/<session>/<timestamp>.jpg) -> /255, no
//      linearisation -> fake HDR (values > threshold times scale) -> 1000 x 500 bicubic if wider -> SH by the
//      official projection (eval/official_sh_projection.h);
//   2. the fixed alignment rot_y(y0) rot_x(x0) rot_z(z0), then rot_y(b) for the `angles` values b of
//      linspace(y_min, y_max) (eval/official_sh_rotation.h);
//   3. for each b, the SHADOWED render under that SH, clamped to [0, 1], and its masked PSNR against the
//      photo; the first b with the highest PSNR is kept (an oracle search on the test photo itself, as in
//      SOL-NeRF; no per-image colour or exposure fit, and the run's learned lighting is not used at all);
//   4. at that b, the shadowed and the unshadowed render (the unshadowed one takes the angle chosen by the
//      shadowed PSNR) scored with the official metrics (io/image_metrics.h) under the evaluation mask: the
//      mask file read as gray (an RGB file: its first channel; cv2 would take the luma, the same for gray
//      masks), resized bilinearly (OpenCV) to the photo's size, eroded once with 5 x 5, and only fully
//      covered pixels kept (the official mask // 255). Without a configured mask, the scene's own mask of the
//      photo is used the same way (not the official protocol; the report says which).
// Means are over images (PSNR averaged as PSNR). Renders are at the resolution the scene was loaded at
// (the official evaluates at the training resolution, -r 1 for NeRF-OSR). A configured photo is evaluated
// whatever its split (the report records it), where the official script silently skips config entries
// that are not test cameras of its split file.
// Known, tiny departures from the official numbers: JPEG decoding (stb_image vs matplotlib/PIL's libjpeg may
// differ by a code value in places), the resampling arithmetic (double here, float or 8-bit fixed point in
// OpenCV) and the search angles (double here, float32 in torch.linspace).
#include <string>
#include <vector>

#include "lumigauss/eval/sheet_panels.h"
#include "lumigauss/eval/sol_nerf_config.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/io/image_metrics.h"
#include "lumigauss/model/surfel_model.h"
#include "lumigauss/render/rasterizer.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/shading/surfel_side.h"

namespace lumigauss {

// linspace(first, last, n) as torch.linspace (the last value exactly `last`; n = 1 gives `first`).
std::vector<double> sol_nerf_angles(double first, double last, int n);

// The environment of step 2 for search angle b (radians) from the official projection's coefficients.
ShCoeffs<double> sol_nerf_environment(const ShCoeffs<double>& projected, const SolNerfImageConfig& image,
                                      double b);

// The evaluation mask of step 4 from a mask file's gray values: resized bilinearly to width x height, eroded
// 5 x 5 once, 1 where fully covered, else 0.
Image sol_nerf_eval_mask(const Image& gray, int width, int height);

// The first index of the largest value (the official keeps an angle only when its PSNR is strictly higher);
// NaN values never win. 0 for an all-NaN list. Throws Error for an empty list.
std::size_t first_best_index(const std::vector<double>& values);

// The scene's view a configured name means: the view of that exact name, else the one whose name without
// extension equals the configured name without extension (NeRF-OSR mixes .JPG, .jpg and .png). nullptr if
// none or ambiguous.
const View* find_sol_nerf_view(const Dataset& scene, const std::string& name);

struct SolNerfImageResult {
    SolNerfImageConfig config;
    std::string view_name;  // the scene's name of the photo
    Split split = Split::Test;
    std::string env_map_path, mask_path;  // files used (mask_path empty: the scene's mask)
    std::size_t boosted_values = 0;       // fake-HDR values multiplied
    std::size_t mask_pixels = 0;
    std::vector<double> angles, search_psnr;  // the search: b (radians) and the shadowed PSNR at each
    std::size_t best_index = 0;
    double best_angle = 0;
    ShCoeffs<double> projected_sh;  // step 1, before any rotation
    ShCoeffs<double> world_sh;      // at the best angle: what the reported renders used
    ImageMetrics shadowed, unshadowed;
    double search_ms = 0;  // wall time of the search renders
    double render_ms = 0;  // wall time of the final render (shadowed + unshadowed + maps)
    SheetPanels panels;    // photo, renders, albedo, normals, shadow, mask (no ground-truth rows)

    bool best_at_range_edge() const {
        return angles.size() > 2 && (best_index == 0 || best_index + 1 == angles.size());
    }
};

struct SolNerfResult {
    std::string config_path;
    int downscale = 1;
    int angles = kSolNerfDefaultAngles;
    std::vector<SolNerfImageResult> images;
    ImageMetrics mean_shadowed, mean_unshadowed;
    double median_render_ms = 0;
    double search_seconds = 0;  // all images
};

struct SolNerfOptions {
    SsimOptions ssim;  // win 5, as the official evaluation
    bool keep_panels = true;
    int angles = 0;  // > 0: overrides the config's count
    SolNerfRoots roots;
    RasterBackend backend = RasterBackend::Cpu;
    SurfelSideRule sides;  // the run's side rule (RelightableRun::side_rule)
};

// Runs the protocol for every image of `config` on `scene` (loaded at the resolution to evaluate) with the
// relightable `model`. Throws Error naming the config file for an image the scene does not have, naming
// the environment or mask file when it is missing or unreadable, and naming the mask when it is empty after
// the erosion.
SolNerfResult evaluate_sol_nerf(const SurfelModel& model, const Dataset& scene, const SolNerfConfig& config,
                                const SolNerfOptions& options = {});

}  // namespace lumigauss
