#pragma once
// The light scale of the gt-env protocol (eval/gt_env.h, steps 1 and 8): the one gauge factor k between a
// run's learned lights and a scene's true ones, fitted on the training photos only.
#include <array>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "lumigauss/eval/gt_scene.h"
#include "lumigauss/eval/relightable_run.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/render/rasterizer.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

// A_l(j)^2, the weight of coefficient j in the irradiance least squares.
double irradiance_weight(int j);

// How directional a learned light is against the true one (luminance: the mean of the channels). Band 1 of
// a degree-2 SH is the light's dipole: its length over the DC says how much more light comes from one side,
// its direction where from. A learned light can match the photos' brightness and still be too flat (the
// sunlit and shaded sides of the scene then differ too little, and the difference goes into albedo and
// shadow transfer): strength < 1.
struct LightDirection {
    double strength = 0;   // (|band 1| / DC) learned over (|band 1| / DC) true; NaN where the truth has none
    double error_deg = 0;  // angle between the learned and true band-1 vectors; NaN likewise
};

// NaN for both when the true light has (nearly) no direction (|band 1| < 0.05 DC) or either DC is <= 0.
LightDirection light_direction(const ShCoeffs<double>& learned, const ShCoeffs<double>& truth);

struct LightScaleFit {
    double scale = 1.0;                     // k
    double relative_residual = 0.0;         // sqrt(sum w |L - k e T|^2 / sum w |L|^2)
    std::vector<std::string> names;         // the training photos used
    std::vector<double> per_photo;          // each photo's own least-squares k_i (diagnostic)
    std::vector<LightDirection> direction;  // per photo (diagnostic)
    // Medians of `direction` over the photos where it is defined; NaN when none is (or nothing was fitted).
    double median_direction_strength = std::numeric_limits<double>::quiet_NaN();
    double median_direction_error_deg = std::numeric_limits<double>::quiet_NaN();
};

// The global k of (1) above from matched lists. Throws Error when the lists are empty, differ in length, or
// the true lighting is all zero.
LightScaleFit fit_light_scale(const std::vector<ShCoeffs<double>>& learned,
                              const std::vector<ShCoeffs<double>>& truth, const std::vector<double>& exposure,
                              const std::vector<std::string>& names = {});

// The run's training photos found in meta.json with split "train" and not in `exclude` (evaluate_gt_env
// passes the test views it evaluates): a test photo never enters the fit. Throws Error naming meta.json
// when no photo is left. A bare PLY (no photos, no learned lights) has nothing to fit: k = 1, no names.
LightScaleFit fit_run_light_scale(const RelightableRun& run, const GtSceneMeta& meta,
                                  const std::vector<std::string>& exclude = {});

// Step 8's scale: per channel, the least-squares scale s_c of the shadowed renders of the training photos
// under exposure * true SH (k = 1) onto the photos, over evaluated, covered (alpha > 0.5), unclipped pixels;
// k_c = s_c^2.2. Photos named in `exclude` are skipped. Nothing when no pixel is usable (a model that covers
// none of them).
std::optional<std::array<double, 3>> fit_image_light_scale(const RelightableRun& run, const Dataset& scene,
                                                           const GtSceneMeta& meta,
                                                           const std::vector<std::string>& exclude,
                                                           RasterBackend backend = RasterBackend::Cpu);

}  // namespace lumigauss
