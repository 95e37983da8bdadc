#pragma once
// The `gt-env` evaluation protocol: a trained run against a scene that ships its true lighting
// (eval/gt_scene.h: meta.json, env/COND_sh.txt and, optionally, gt/{mask,albedo,normal}).
//
// 1. Light scale. The model shades albedo_m * max(E_m, 1e-5)^(1/2.2) (shading/surfel_shading.h), and a photo
//    is srgb(exposure * rho/pi * E_true) (data/plaza README). Since srgb(x) ~ x^(1/2.2), the fit has a gauge:
//    albedo_m * c with E_m * c^(-2.2) renders the same, so the learned SH of training photo i is, at best,
//    k * exposure_i * (true SH of its condition) for ONE unknown k shared by all photos. k is estimated from
//    the TRAINING photos only (learned SH from the lighting MLP, true SH from meta.json), never from a test
//    photo, as the least-squares fit of the irradiance over the whole sphere of normals:
//        k = argmin sum_i integral_{S^2} |E[L_i](n) - k e_i E[T_i](n)|^2 dn
//          = sum_i e_i sum_{j,c} A_l(j)^2 L_ijc T_ijc  /  sum_i e_i^2 sum_{j,c} A_l(j)^2 T_ijc^2,
//    (orthonormality of the SH turns the integral into the A_l^2-weighted sum over the 27 coefficients;
//    A_0 = pi, A_1 = 2pi/3, A_2 = pi/4), so band 0 and 1, which carry most of the irradiance, dominate.
// 2. Each test photo is rendered under env = k * exposure_test * (true SH of its condition): no rotation
//    search, no per-image colour fit. Using the test photo's exposure is allowed: it is the camera's setting
//    (recorded with the photo, like EXIF), not a property of the lighting; the data sets fix it to 1.0 for
//    test photos anyway.
// 3. Image metrics (io/image_metrics.h, official formulas) of the render clamped to [0, 1] against the photo,
//    shadowed and unshadowed, under the evaluation mask: gt/mask (geometry coverage) eroded once with 5x5
//    and kept where fully covered, times the scene's own mask (masks/, binarised at 0.5) if it has one.
//    Without gt/mask the scene's mask alone is eroded and binarised the same way.
// 4. Albedo (when gt/albedo exists): the model's albedo max(0, Y00 a + 0.5) rasterised with its geometry
//    (black background). That albedo lives in the model's gamma-2.2 domain (it multiplies E^(1/2.2)), so it
//    is compared (a) linearised, a^2.2, against gt/albedo ("albedo", primary) and (b) as it is against
//    gt/albedo^(1/2.2) ("albedo_gamma"), each after ONE per-channel least-squares scale pooled over all test
//    images' masked pixels, then clamped to [0, 1]; PSNR/MSE/MAE with the official formulas.
// 5. Sky (when gt/mask exists): the share of the pixels that see no geometry (gt/mask = 0) where the
//    render's alpha exceeds 0.5. A run trained with the sky background (config.json "sky_background") is
//    rendered as it was trained, the sky of the evaluation light drawn behind its surfels (the metrics'
//    mask excludes the sky, so this changes the pixels the model leaves empty or partly transparent, and the
//    contact sheets).
// 6. Empty pixels: the share of the evaluated pixels where the render's alpha is at most 0.5 (the model has
//    no surface there, e.g. ground that no training photo sees closely), and the shadowed PSNR over the
//    rest. A diagnostic beside the metrics of 3, which score every evaluated pixel.
// 7. Normals (when gt/normal exists): the rasterised world normal map, normalised, against gt/normal decoded
//    as 2v - 1 and normalised; angles in degrees over the evaluation mask; a pixel with no rendered normal
//    counts as 90 deg. Per image mean and median; overall the mean of those and the pooled statistics.
// 8. A second light scale, fitted where the model is observed: the shadowed renders of the TRAINING photos
//    under exposure * true SH, fitted to those photos in image space, one scale per channel (covered,
//    unclipped pixels of their evaluation masks; never a test photo). Step 1 compares SH coefficients over
//    the whole sphere of normals, so it also weighs what no photo constrains (light from below; the learned
//    lights' irradiance of a downward normal is 0.5-2 times that of an upward one on plaza, the truth's
//    0.05), and one scalar cannot follow the model's colour gauge (albedo_c * s_c with E_c * s_c^(-2.2)
//    renders every training photo the same, for each channel apart). The test views are scored again under
//    k_c * exposure * true SH ("image-scaled"); the metrics of 3 stay the protocol's headline.
// 9. By surface (when gt/normal exists): the evaluated pixels split by the true normal into those facing up
//    (within 25 deg of +z, the scenes' up: ground, terraces) and the rest (walls, roofs, columns), each with
//    its shadowed PSNR (squared error pooled over the scored images) and the least-squares gain per channel
//    that would take the render onto the photo there. Gains near 1 on one and not on the other say that the
//    model's albedo of one kind of surface is off against the other's (on plaza the walls come out a third
//    too dark: bench/RESULTS.md, session 35), which no light scale can fix.
// 10. What the photos can tell about their lights (when the training photos have gt/albedo and gt/normal;
//    light_reference.h): the residual of step 1 on the part of each light its photo's normals see, and the
//    residual of lights fitted to the photos' shading with the true albedo and normals (a reference for
//    step 1's residual, as 21.26 dB is for the PSNR on plaza).
// Ground-truth images are area-resampled to the evaluated resolution (-r) like the photos.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "lumigauss/eval/gt_scene.h"
#include "lumigauss/eval/light_reference.h"
#include "lumigauss/eval/light_scale.h"
#include "lumigauss/eval/relightable_run.h"
#include "lumigauss/eval/sheet_panels.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/io/image_metrics.h"
#include "lumigauss/render/rasterizer.h"
#include "lumigauss/shading/sky_image.h"

namespace lumigauss {

struct AlbedoMetrics {
    double psnr = 0, mse = 0, mae = 0;
};

// Sums over the pixels of one kind of surface (header, step 9), shadowed render against the photo.
struct SurfaceRegion {
    std::size_t pixels = 0;
    double squared_error = 0;                  // summed over the pixels and the three channels
    std::array<double, 3> photo_dot_render{};  // sum of photo x render, per channel
    std::array<double, 3> render_squared{};    // sum of render^2, per channel
    SurfaceRegion& operator+=(const SurfaceRegion& o);
    double psnr() const;             // NaN without pixels
    double gain(int channel) const;  // least-squares photo / render; NaN without pixels
};
struct SurfaceSplit {
    SurfaceRegion up, other;
};
// The true normals within this angle of +z count as facing up.
inline constexpr double kUpFacingDeg = 25.0;

struct GtEnvImageResult {
    std::string name, condition;
    double exposure = 1.0;
    std::size_t mask_pixels = 0;
    double render_ms = 0;  // wall time of the one 6-channel render (shadowed + unshadowed + maps)
    // Sky pixels (gt/mask exactly 0), the share of them where the render's alpha exceeds 0.5 (surfels
    // painting the sky seen from a new viewpoint) and their mean alpha (a faint veil in front of the camera);
    // eval/sky_coverage.h. 0 pixels when the scene has no gt/mask.
    std::size_t sky_pixels = 0;
    double sky_alpha_fraction = 0;
    double sky_mean_alpha = 0;
    // Evaluated pixels the model leaves empty (alpha <= 0.5): geometry no training photo pinned down, drawn
    // as background. The shadowed PSNR over the other evaluated pixels separates that from the shading error
    // (NaN when the model covers none of them).
    double empty_fraction = 0;
    double covered_shadowed_psnr = 0;
    ImageMetrics shadowed, unshadowed;
    ImageMetrics image_scaled_shadowed;  // shadowed, under the image-space light scale (header, step 8)
    bool has_albedo = false, has_normal = false;
    AlbedoMetrics albedo, albedo_gamma;
    AngularErrorStats normal;
    SurfaceSplit surfaces;  // header, step 9 (with has_normal)
    SheetPanels panels;
};

struct GtEnvResult {
    Split views = Split::Test;  // which photos were scored (GtEnvOptions::views)
    LightScaleFit light;
    // What the training photos can tell about their lights (light_reference.h); nothing without gt/albedo
    // and gt/normal or when GtEnvOptions::light_reference is off.
    std::optional<LightReference> light_reference;
    bool image_scaled = false;  // step 8 ran (GtEnvOptions::image_light_scale) and found usable pixels
    std::array<double, 3> image_light_scale{1, 1, 1};  // its k per channel
    int downscale = 1;
    bool sky_behind = false;  // the run was trained with its sky behind the surfels: drawn (true_sky_image)
    SkyHorizon sky_horizon;   // ... above this horizon
    bool gt_mask = false;     // every test image had a gt/mask
    bool has_albedo = false, has_normal = false;  // every test image had gt/albedo, gt/normal
    std::vector<GtEnvImageResult> images;
    // Means over images (PSNR averaged as PSNR, as officially).
    ImageMetrics mean_shadowed, mean_unshadowed;
    ImageMetrics mean_image_scaled_shadowed;
    double median_render_ms = 0;
    bool has_sky = false;                   // some scored image had sky pixels
    double sky_alpha_fraction = 0;          // over every sky pixel of every scored image
    double sky_mean_alpha = 0;              // the mean alpha over those pixels
    double empty_fraction = 0;              // over every evaluated pixel of every scored image
    double mean_covered_shadowed_psnr = 0;  // mean over the images that have covered pixels
    std::array<double, 3> albedo_scale{1, 1, 1}, albedo_gamma_scale{1, 1, 1};
    AlbedoMetrics mean_albedo, mean_albedo_gamma;
    AngularErrorStats mean_normal;    // mean of the per-image means and of the per-image medians
    AngularErrorStats pooled_normal;  // over every measured pixel of every test image
    SurfaceSplit surfaces;            // summed over the scored images (with has_normal)
};

struct GtEnvOptions {
    SsimOptions ssim;  // win 5, as the official evaluation
    bool keep_panels = true;
    // Which photos are scored. Test (the protocol): novel views under novel lights. Train is a diagnostic
    // that separates the lighting model from novel-view geometry: the training views, each rendered under its
    // own TRUE environment (not the learned one); the light scale is then fitted on all training photos.
    Split views = Split::Test;
    RasterBackend backend = RasterBackend::Cpu;
    // Step 8: also fit the light scale per channel on the training images and score the test views under it.
    bool image_light_scale = true;
    // Also fit the reference lights with the true albedo and normals of the training photos.
    bool light_reference = true;
};

// Runs the protocol on every test view of `scene` (loaded at the resolution to evaluate). Throws Error
// naming the file for a test photo missing from meta.json, a missing SH file, or an empty evaluation mask.
GtEnvResult evaluate_gt_env(const RelightableRun& run, const Dataset& scene, const GtSceneMeta& meta,
                            const GtEnvOptions& options = {});

}  // namespace lumigauss
