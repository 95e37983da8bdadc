#pragma once
// Estimating the environment of a new photo of a trained scene with the model frozen (`lumigauss
// fit-light`, and the `holdout` evaluation protocol).
//
// The photo is rendered from its camera as in training (black background, no SH noise) and the lighting is
// optimised with Adam against the training objective restricted to what depends on the light:
//   (1 - lambda_dssim) L1 + lambda_dssim D-SSIM   of the shadowed (or unshadowed) render, masked,
//   + lambda_env l_+                             the environment stays non-negative on the sphere.
// Two parameterisations:
//   * Sh: the 27 radiance SH coefficients directly. Works for any model (also a bare PLY with no lighting
//     network); from the mean of the run's learned lights, or a neutral grey sky (irradiance 1) without one.
//   * Embedding: a new 24-float embedding through the run's frozen lighting MLP (the NeRF-W way to fit the
//     appearance of a test photo). The light stays on the manifold of lights seen in training, which is
//     more robust when only part of the photo is seen (holdout). Starts from the mean training embedding.
// A run trained with its sky behind the surfels is fitted as it was trained: the sky of the light fills what
// the surfels leave uncovered; when the run learned a sky residual per photo, the photo gets one too (from
// zero, under the run's L2 weight), and when its sky did not shape its lights (config sky_pins_light=false)
// the sky's pixels move that residual only, so that the light is the surfels' alone.
// The geometry and the transfer functions are fixed, so the visibility of every pixel is computed once:
// each iteration re-shades the surfels, re-rasterises and back-propagates only to the light.
//
// Units: the result lives in the model's gauge (the albedo scale learned with the training lights), i.e. it
// is the light to render THIS model with, not a physically calibrated one.
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/io/image.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/shading/sh_degree4.h"

namespace lumigauss {

enum class LightVariable { Sh, Embedding };

const char* light_variable_name(LightVariable v);  // "sh", "embedding"

struct LightFitOptions {
    LightVariable variable = LightVariable::Sh;
    bool shadowed = true;  // fit the shadowed render (false: the unshadowed one)
    int iterations = 300;
    // Adam learning rates, decayed log-linearly to final_lr_fraction of themselves over the iterations.
    double sh_learning_rate = 0.02;
    double embedding_learning_rate = 0.05;
    double final_lr_fraction = 0.05;
    double lambda_dssim = 0.2;  // as training (train_config.h)
    double lambda_env = 0.05;   // l_+ weight, as training
    int env_samples = 10;       // directions per iteration for l_+, as training
    std::uint64_t seed = 0;
    std::optional<ShCoeffs<double>> initial_sh;           // Sh: start here instead of the default
    std::optional<std::vector<float>> initial_embedding;  // Embedding: 24 floats
    // Called after every iteration with (iteration, loss, masked PSNR of the render being fitted).
    std::function<void(int, double, double)> progress;
};

struct LightFitResult {
    ShCoeffs<double> sh;  // the fitted environment radiance SH (world frame)
    // The photo's fitted sky residual, when the run has them (TrainedRun::sky_residuals): its sky is drawn
    // from sh plus this.
    std::optional<Sh4Coeffs<float>> sky_residual;
    std::vector<float> embedding;  // Embedding: the fitted embedding; empty for Sh
    int iterations = 0;
    double initial_loss = 0, final_loss = 0;  // objective above, at the start and at the result
    double initial_psnr = 0, final_psnr = 0;  // masked PSNR (official formula) of the fitted render
    double env_loss = 0;                      // l_+ of the result (0: non-negative everywhere sampled)
};

// Fits the lighting of `photo` (3 channels in [0, 1], the size of `camera`) seen from `camera`. `mask`
// (empty, or 1 channel of the same size, soft values allowed) selects the pixels that count. Returns the
// iterate with the lowest objective. Throws Error when the sizes disagree, the mask is empty, the model has
// no surfel in view, or Embedding is asked of a run without a lighting network.
LightFitResult fit_light(const TrainedRun& run, const Camera& camera, const Image& photo, const Image& mask,
                         const LightFitOptions& options);

// Channels [first, first + 3) of a render (`relit`: relit_render.h's layout, or any colour raster with
// first = 0) as the fit compares it with the photo: over the sky of `light` (plus `sky_residual`, when given)
// when the run was trained with its sky behind the surfels (else over black), clamped to [0, 1].
Image fitted_colour(const TrainedRun& run, const Camera& camera, const RasterImages<float>& relit, int first,
                    const ShCoeffs<double>& light, const Sh4Coeffs<float>* sky_residual = nullptr);
// The same under a fit's light and sky.
Image fitted_colour(const TrainedRun& run, const Camera& camera, const RasterImages<float>& relit, int first,
                    const LightFitResult& fit);

// The default starting light: the mean learned SH of the run's photos, or a neutral grey environment with
// irradiance 1 in every direction when the run has none (a bare PLY).
ShCoeffs<double> default_initial_sh(const TrainedRun& run);

}  // namespace lumigauss
