#pragma once
// The `holdout` evaluation protocol, for photo collections without ground-truth lighting (NeRF-W's
// "appearance from the left half"): the lighting of each test photo is fitted with the model frozen
// (relight/light_fit.h) on the LEFT half of the photo only, and the render under that light is scored on
// the RIGHT half, which the fit never saw. Scores novel-view geometry, albedo and the transfer functions
// under a light the model could explain, without any ground-truth environment.
//
//   fit mask    the scene's mask (soft values as stored; all ones without one) on columns x < W/2
//   score mask  official_eval_mask (io/image_metrics.h: 5x5 erosion, fully covered pixels) of the scene's
//               mask binarised at 0.5 less the view's sky mask (when the scene has one), on columns x >= W/2
// The sky is left out of the score as NeRF-OSR's evaluation masks leave it out (and gt-env's gt/mask): a
// sky is not relit geometry, and a run whose sky is a per-photo residual free of its light (config
// sky_pins_light=false) can only extrapolate the right half's sky from the left's. The fit still sees the
// left half's sky as training saw its photos' skies.
// Each render is scored under its own fit: the shadowed render under the light fitted to the shadowed render,
// the unshadowed one under the light fitted to the unshadowed render, so that neither is judged with a
// light tuned for the other (an unshadowed model compensates missing shadows with a dimmer light).
#include <functional>
#include <string>
#include <vector>

#include "lumigauss/eval/sheet_panels.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/io/image.h"
#include "lumigauss/io/image_metrics.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/relight/light_fit.h"
#include "lumigauss/render/rasterizer.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

struct HoldoutImageResult;

struct HoldoutOptions {
    LightFitOptions fit;  // variable, iterations, ... (`shadowed` is set per fit)
    SsimOptions ssim;     // win 5, as the official evaluation
    Split views = Split::Test;
    bool keep_panels = true;
    // false: the shadowed render only (one fit per photo instead of two); the unshadowed scores are NaN.
    bool unshadowed = true;
    // > 0: at most this many photos of the split, spread evenly over it (views i * count / max_views).
    std::size_t max_views = 0;
    RasterBackend backend = RasterBackend::Cpu;  // the scoring renders (the fits run on the CPU)
    // Called after each photo (its result, how many are done, how many in all): each fit takes seconds, a
    // collection minutes, so the command shows them as they come.
    std::function<void(const HoldoutImageResult&, std::size_t done, std::size_t total)> on_image;
};

struct HoldoutImageResult {
    std::string name;
    std::size_t fit_pixels = 0, score_pixels = 0;
    // Masked PSNR of each fitted render on the left half (how well the fit went).
    double fit_psnr = 0, fit_psnr_unshadowed = 0;
    double fit_ms = 0, render_ms = 0;
    ShCoeffs<double> light;             // the environment SH fitted to the shadowed render
    ShCoeffs<double> light_unshadowed;  // ... and to the unshadowed one
    ImageMetrics shadowed, unshadowed;  // on the right half
    // The contact sheet's panels (eval/sheet_panels.h): photo, clamped renders under their fitted lights,
    // albedo (clamped), normals, shadow image, and as `mask` the score mask. No ground-truth panels.
    SheetPanels panels;
};

struct HoldoutResult {
    LightVariable variable = LightVariable::Sh;
    int iterations = 0;
    Split views = Split::Test;
    std::vector<HoldoutImageResult> images;
    ImageMetrics mean_shadowed, mean_unshadowed;  // PSNR averaged as PSNR, as officially
    double mean_fit_psnr = 0, mean_fit_psnr_unshadowed = 0, median_fit_ms = 0, median_render_ms = 0;
};

// Fit mask and score mask of a view (see above) from the scene's mask as loaded (empty: no mask).
Image holdout_fit_mask(const Image& scene_mask, int width, int height);
// `sky_mask` (empty, or 1 channel of the image's size, 1 = sky) is taken out of the score mask.
Image holdout_score_mask(const Image& scene_mask, int width, int height, const Image& sky_mask = {});

// Runs the protocol on the views of `scene` (loaded at the resolution to evaluate). Throws Error naming
// the image when a half has no pixel to fit or to score.
HoldoutResult evaluate_holdout(const TrainedRun& run, const Dataset& scene, const HoldoutOptions& options);

}  // namespace lumigauss
