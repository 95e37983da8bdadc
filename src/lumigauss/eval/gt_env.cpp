#include "lumigauss/eval/gt_env.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>

#include "lumigauss/eval/sky_coverage.h"
#include "lumigauss/relight/relit_render.h"
#include "lumigauss/relight/relit_sky.h"
#include "lumigauss/render/raster_maps.h"
#include "lumigauss/shading/sky_image.h"
#include "lumigauss/shading/surfel_shading.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
SurfaceRegion& SurfaceRegion::operator+=(const SurfaceRegion& o) {
    pixels += o.pixels, squared_error += o.squared_error;
    for (int c = 0; c < 3; ++c)
        photo_dot_render[c] += o.photo_dot_render[c], render_squared[c] += o.render_squared[c];
    return *this;
}

double SurfaceRegion::psnr() const {
    return pixels > 0 ? psnr_from_mse(squared_error / (3.0 * double(pixels)))
                      : std::numeric_limits<double>::quiet_NaN();
}

double SurfaceRegion::gain(int channel) const {
    return pixels > 0 && render_squared[channel] > 0 ? photo_dot_render[channel] / render_squared[channel]
                                                     : std::numeric_limits<double>::quiet_NaN();
}

namespace {

namespace fs = std::filesystem;

constexpr double kGamma = 1.0 / surfel_const::kInvGamma;  // 2.2, the model's light-to-colour exponent

Image map_values(const Image& im, double (*f)(double)) {
    Image out = im;
    for (float& v : out.pixels) v = float(f(double(v)));
    return out;
}

double to_linear(double v) {
    return std::pow(std::max(v, 0.0), kGamma);
}
double to_gamma(double v) {
    return std::pow(std::max(v, 0.0), 1.0 / kGamma);
}

// The sky behind a view lit by `scale` x exposure x its condition's true light: the condition's panorama
// when the scene has it, so that the sheets show the sky the photo shows rather than the ringing of its
// degree-2 SH; else that SH. Either ends below the run's horizon (holes in the ground are not drawn with the
// true environment's lower half).
Image true_sky_image(const RelightableRun& run, const GtSceneMeta& meta, TruePanoramas& panoramas,
                     const GtImageMeta& im, const Camera& camera, const std::array<double, 3>& scale) {
    if (const Image* panorama = panoramas.find(im.condition)) {
        PanoramaSky sky;
        sky.pixels = panorama;
        sky.factor = im.exposure * Vec3d{scale[0], scale[1], scale[2]};
        sky.horizon = run.sky_horizon;
        sky.ground = horizon_ground_colour(scaled_true_env(meta, im, scale), run.sky_horizon);
        return panorama_sky_image(camera, sky);
    }
    return sky_image(camera, scaled_true_env(meta, im, scale), nullptr, run.sky_horizon);
}

// The shadowed render of a view under scale x exposure x its true light, clamped, with the sky behind it
// when the run was trained so.
Image shadowed_panel(const RelightableRun& run, const GtSceneMeta& meta, TruePanoramas& panoramas,
                     const GtImageMeta& im, RelitRenderer& renderer, const Camera& camera,
                     const std::array<double, 3>& scale) {
    const RasterImages<float>& relit = renderer.render(camera, scaled_true_env(meta, im, scale));
    Image shadowed = raster_channels(relit, kRelitShadowed, 3);
    if (run.sky_background)
        shadowed = over_background_image(shadowed, alpha_image(relit),
                                         true_sky_image(run, meta, panoramas, im, camera, scale));
    return clamp01(shadowed);
}

AlbedoMetrics albedo_metrics(const Image& predicted, const Image& truth, const Image& mask) {
    AlbedoMetrics m;
    m.mse = masked_mse(predicted, truth, mask);
    m.mae = masked_mae(predicted, truth, mask);
    m.psnr = psnr_from_mse(m.mse);
    return m;
}

// What the first pass keeps for the pooled albedo scale.
struct AlbedoInputs {
    Image rendered;  // model albedo (gamma domain), unclamped
    Image truth;     // gt/albedo, linear; empty when the scene has none for the view
};

// What every view of one evaluation shares.
struct Evaluation {
    const RelightableRun& run;
    const Dataset& scene;
    const GtSceneMeta& meta;
    const GtEnvOptions& options;
    RelitRenderer renderer;  // one pass per view gives both colours, both intensities and the albedo
    TruePanoramas panoramas;
    std::vector<AlbedoInputs> albedo_inputs;  // per scored view
    std::vector<double> pooled_angles;        // normal errors of every measured pixel
    bool every_gt_mask = true;                // every scored view had a gt/mask
};

// Sky pixels (gt/mask exactly 0) of a view: the share the render covers (alpha > 0.5) and its mean alpha.
void score_sky(const Image& coverage, const RasterImages<float>& relit, GtEnvImageResult& r) {
    const SkyCoverage sky = sky_coverage(coverage, relit.alpha);
    r.sky_pixels = sky.pixels;
    r.sky_alpha_fraction = sky.covered;
    r.sky_mean_alpha = sky.mean_alpha;
}

// The evaluated pixels the render leaves empty, and the shadowed PSNR over the others (header, step 6).
void score_empty_pixels(const RasterImages<float>& relit, GtEnvImageResult& r) {
    const SheetPanels& p = r.panels;
    Image covered_mask = p.mask;
    for (std::size_t q = 0; q < covered_mask.pixels.size(); ++q)
        if (relit.alpha[q] <= 0.5f) covered_mask.pixels[q] = 0.0f;
    const std::size_t covered_pixels = mask_pixels(covered_mask);
    r.empty_fraction = 1.0 - double(covered_pixels) / double(r.mask_pixels);
    r.covered_shadowed_psnr = covered_pixels > 0
                                  ? psnr_from_mse(masked_mse(p.shadowed, p.truth, covered_mask))
                                  : std::numeric_limits<double>::quiet_NaN();
}

// The shadowed render against the photo over the evaluated pixels, split by the true normal (header, step 9).
// `decoded` holds the true normals (2v - 1).
SurfaceSplit split_by_surface(const SheetPanels& p, const Image& decoded) {
    SurfaceSplit split;
    const double cos_up = std::cos(kUpFacingDeg * std::numbers::pi / 180.0);
    for (std::size_t q = 0; q < p.mask.pixels.size(); ++q) {
        if (!(p.mask.pixels[q] > 0.5f)) continue;
        const Vec3d n{decoded.pixels[3 * q], decoded.pixels[3 * q + 1], decoded.pixels[3 * q + 2]};
        const double len = length(n);
        SurfaceRegion& r = len > 0 && n.z / len > cos_up ? split.up : split.other;
        ++r.pixels;
        for (int c = 0; c < 3; ++c) {
            const double render = p.shadowed.pixels[3 * q + c], photo = p.truth.pixels[3 * q + c];
            r.squared_error += (render - photo) * (render - photo);
            r.photo_dot_render[c] += photo * render;
            r.render_squared[c] += render * render;
        }
    }
    return split;
}

// The rendered normals against gt/normal (header, step 7), and the error panel.
void score_normals(const std::string& gt_normal_path, const Image& rendered_normal, GtEnvImageResult& r,
                   std::vector<double>& pooled_angles) {
    SheetPanels& p = r.panels;
    const int w = rendered_normal.width, h = rendered_normal.height;
    r.has_normal = true;
    p.gt_normal = load_gt_image(gt_normal_path, w, h, 3);
    Image decoded = p.gt_normal;
    for (float& x : decoded.pixels) x = 2.0f * x - 1.0f;
    r.normal = normal_angular_error(rendered_normal, decoded, p.mask, 1e-3, &pooled_angles);
    r.surfaces = split_by_surface(p, decoded);
    p.normal_error = Image(w, h, 1);
    for (std::size_t q = 0; q < p.normal_error.pixels.size(); ++q) {
        if (!(p.mask.pixels[q] > 0.5f)) continue;
        const Vec3d a{rendered_normal.pixels[3 * q], rendered_normal.pixels[3 * q + 1],
                      rendered_normal.pixels[3 * q + 2]};
        const Vec3d b{decoded.pixels[3 * q], decoded.pixels[3 * q + 1], decoded.pixels[3 * q + 2]};
        const double angle = length(a) > 1e-3 ? angle_deg(a, b) : 90.0;
        p.normal_error.pixels[q] = std::isfinite(angle) ? float(std::min(1.0, angle / 45.0)) : 0.f;
    }
}

// One view rendered under k * exposure * its true light and scored (header, steps 2-8 but the pooled
// albedo scale).
GtEnvImageResult evaluate_view(Evaluation& e, const View& v, const GtEnvResult& result) {
    const GtImageMeta* im = e.meta.find(v.name);
    if (!im) fail_in_file(e.meta.meta_path, "no entry for test image '" + v.name + "'");
    GtEnvImageResult r;
    r.name = v.name;
    r.condition = im->condition;
    r.exposure = im->exposure;
    const int w = v.camera.width, h = v.camera.height;

    const double k = result.light.scale;
    const ShCoeffs<float> env = scaled_true_env(e.meta, *im, {k, k, k});
    const auto t0 = std::chrono::steady_clock::now();
    const RasterImages<float>& relit = e.renderer.render(v.camera, env);
    r.render_ms = 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    SheetPanels& p = r.panels;
    p.shadowed = raster_channels(relit, kRelitShadowed, 3);
    p.unshadowed = raster_channels(relit, kRelitUnshadowed, 3);
    if (e.run.sky_background) {
        const Image sky = true_sky_image(e.run, e.meta, e.panoramas, *im, v.camera, {k, k, k});
        const Image alpha = alpha_image(relit);
        p.shadowed = over_background_image(p.shadowed, alpha, sky);
        p.unshadowed = over_background_image(p.unshadowed, alpha, sky);
    }
    p.shadowed = clamp01(p.shadowed);
    p.unshadowed = clamp01(p.unshadowed);
    p.truth = e.scene.load_image(v);

    const std::string gt_mask_path = gt_image_path(e.meta.root, "mask", v.name);
    bool has_gt_mask = false;
    p.mask = evaluation_mask(e.meta, e.scene, v, has_gt_mask);
    e.every_gt_mask = e.every_gt_mask && has_gt_mask;
    r.mask_pixels = mask_pixels(p.mask);
    if (r.mask_pixels == 0)
        fail_in_file(has_gt_mask ? gt_mask_path : v.image_path,
                     "the evaluation mask is empty (no fully covered pixel after the 5x5 erosion)");
    if (has_gt_mask) score_sky(load_gt_image(gt_mask_path, w, h, 1), relit, r);
    r.shadowed = image_metrics(p.shadowed, p.truth, p.mask, e.options.ssim);
    r.unshadowed = image_metrics(p.unshadowed, p.truth, p.mask, e.options.ssim);
    score_empty_pixels(relit, r);

    // The paper's shadow image (as `render` writes it) and the model's albedo and normal maps.
    p.shadow = shadow_image(raster_channels(relit, kRelitIntensityUnshadowed, 3),
                            raster_channels(relit, kRelitIntensityShadowed, 3));
    p.normal = encode_normals(relit);
    AlbedoInputs albedo{raster_channels(relit, kRelitAlbedo, 3), Image()};
    if (const std::string path = gt_image_path(e.meta.root, "albedo", v.name); fs::exists(path)) {
        r.has_albedo = true;
        albedo.truth = load_gt_image(path, w, h, 3);
        p.gt_albedo = map_values(albedo.truth, to_gamma);
    }
    e.albedo_inputs.push_back(std::move(albedo));
    if (const std::string path = gt_image_path(e.meta.root, "normal", v.name); fs::exists(path)) {
        Image rendered_normal(w, h, 3);
        rendered_normal.pixels = relit.normal;
        score_normals(path, rendered_normal, r, e.pooled_angles);
    }
    // The same view under the image-space light scale (a second render: the sky and the clamp follow it).
    if (result.image_scaled)
        r.image_scaled_shadowed = image_metrics(
            shadowed_panel(e.run, e.meta, e.panoramas, *im, e.renderer, v.camera, result.image_light_scale),
            p.truth, p.mask, e.options.ssim);
    return r;
}

// Albedo (header, step 4): one per-channel scale per domain, pooled over every scored view, when every one
// of them has a ground truth; else no albedo metrics at all.
void score_albedo(const std::vector<AlbedoInputs>& inputs, GtEnvResult& result) {
    result.has_albedo = !inputs.empty();
    for (const AlbedoInputs& in : inputs) result.has_albedo = result.has_albedo && !in.truth.empty();
    if (!result.has_albedo) {
        for (GtEnvImageResult& r : result.images) {
            r.has_albedo = false;
            r.panels.gt_albedo = Image();
        }
        return;
    }
    ScaleFitTerms lin_terms, gam_terms;
    std::vector<Image> lin_pred, gam_pred, lin_truth, gam_truth;
    for (std::size_t i = 0; i < inputs.size(); ++i) {
        const Image& mask = result.images[i].panels.mask;
        lin_pred.push_back(map_values(inputs[i].rendered, to_linear));
        gam_pred.push_back(map_values(inputs[i].rendered, [](double x) { return std::max(x, 0.0); }));
        lin_truth.push_back(inputs[i].truth);
        gam_truth.push_back(map_values(inputs[i].truth, to_gamma));
        add_scale_terms(lin_pred[i], lin_truth[i], mask, lin_terms);
        add_scale_terms(gam_pred[i], gam_truth[i], mask, gam_terms);
    }
    const std::array<double, 4> lin_scale = scale_from_terms(lin_terms),
                                gam_scale = scale_from_terms(gam_terms);
    for (int c = 0; c < 3; ++c)
        result.albedo_scale[c] = lin_scale[c], result.albedo_gamma_scale[c] = gam_scale[c];
    for (std::size_t i = 0; i < inputs.size(); ++i) {
        GtEnvImageResult& r = result.images[i];
        const Image lin = clamp01(scale_channels(lin_pred[i], lin_scale));
        const Image gam = clamp01(scale_channels(gam_pred[i], gam_scale));
        r.albedo = albedo_metrics(lin, lin_truth[i], r.panels.mask);
        r.albedo_gamma = albedo_metrics(gam, gam_truth[i], r.panels.mask);
        r.panels.albedo = gam;
    }
}

// Normals over all views: the mean of the per-image statistics and the pooled ones, when every view has a
// ground truth.
void summarize_normals(std::vector<double> pooled_angles, GtEnvResult& result) {
    std::size_t normal_images = 0, missing = 0;
    for (const GtEnvImageResult& r : result.images) {
        if (!r.has_normal || r.normal.pixels == 0) continue;
        ++normal_images;
        result.mean_normal.mean_deg += r.normal.mean_deg;
        result.mean_normal.median_deg += r.normal.median_deg;
        result.mean_normal.pixels += r.normal.pixels;
        result.mean_normal.missing += r.normal.missing;
        missing += r.normal.missing;
    }
    result.has_normal = normal_images > 0 && normal_images == result.images.size();
    if (!result.has_normal) return;
    result.mean_normal.mean_deg /= double(normal_images);
    result.mean_normal.median_deg /= double(normal_images);
    result.pooled_normal = angle_stats(std::move(pooled_angles));
    result.pooled_normal.missing = missing;
}

// Means over the views (PSNR averaged as PSNR, as officially), sky and empty-pixel shares over all pixels,
// the median render time.
void summarize_views(GtEnvResult& result) {
    const double n = double(result.images.size());
    auto add_metrics = [n](ImageMetrics& sum, const ImageMetrics& m) {
        sum.psnr += m.psnr / n, sum.ssim += m.ssim / n, sum.mse += m.mse / n, sum.mae += m.mae / n;
    };
    auto add_albedo = [n](AlbedoMetrics& sum, const AlbedoMetrics& m) {
        sum.psnr += m.psnr / n, sum.mse += m.mse / n, sum.mae += m.mae / n;
    };
    std::size_t sky_pixels = 0, evaluated = 0, covered_images = 0;
    double sky_covered = 0, sky_alpha = 0, empty = 0;
    std::vector<double> render_ms;
    for (const GtEnvImageResult& r : result.images) {
        add_metrics(result.mean_shadowed, r.shadowed);
        add_metrics(result.mean_image_scaled_shadowed, r.image_scaled_shadowed);
        add_metrics(result.mean_unshadowed, r.unshadowed);
        if (result.has_albedo)
            add_albedo(result.mean_albedo, r.albedo), add_albedo(result.mean_albedo_gamma, r.albedo_gamma);
        sky_pixels += r.sky_pixels, sky_covered += r.sky_alpha_fraction * double(r.sky_pixels);
        sky_alpha += r.sky_mean_alpha * double(r.sky_pixels);
        evaluated += r.mask_pixels, empty += r.empty_fraction * double(r.mask_pixels);
        if (!std::isnan(r.covered_shadowed_psnr))
            result.mean_covered_shadowed_psnr += r.covered_shadowed_psnr, ++covered_images;
        render_ms.push_back(r.render_ms);
        result.surfaces.up += r.surfaces.up, result.surfaces.other += r.surfaces.other;
    }
    result.empty_fraction = evaluated > 0 ? empty / double(evaluated) : 0.0;
    result.mean_covered_shadowed_psnr = covered_images > 0
                                            ? result.mean_covered_shadowed_psnr / double(covered_images)
                                            : std::numeric_limits<double>::quiet_NaN();
    result.has_sky = sky_pixels > 0;
    result.sky_alpha_fraction = result.has_sky ? sky_covered / double(sky_pixels) : 0.0;
    result.sky_mean_alpha = result.has_sky ? sky_alpha / double(sky_pixels) : 0.0;
    if (!render_ms.empty()) {
        std::sort(render_ms.begin(), render_ms.end());
        result.median_render_ms = render_ms[render_ms.size() / 2];
    }
}

}  // namespace

GtEnvResult evaluate_gt_env(const RelightableRun& run, const Dataset& scene, const GtSceneMeta& meta,
                            const GtEnvOptions& options) {
    GtEnvResult result;
    result.downscale = scene.downscale;
    result.views = options.views;
    result.sky_behind = run.sky_background;
    result.sky_horizon = run.sky_horizon;
    const std::vector<const View*> views = scene.split(options.views);
    if (views.empty())
        throw Error(scene.root + ": the scene has no " + split_name(options.views) + " image to evaluate");
    std::vector<std::string> test_names;  // excluded from the light-scale fits
    if (options.views != Split::Train)
        for (const View* v : views) test_names.push_back(v->name);
    result.light = fit_run_light_scale(run, meta, test_names);
    if (options.light_reference) result.light_reference = light_reference(run, scene, meta, test_names);
    if (options.image_light_scale)
        if (const auto k = fit_image_light_scale(run, scene, meta, test_names, options.backend)) {
            result.image_scaled = true;
            result.image_light_scale = *k;
        }

    Evaluation e{run,
                 scene,
                 meta,
                 options,
                 RelitRenderer(run.model, options.backend, run.side_rule),
                 TruePanoramas(meta),
                 {},
                 {}};
    for (const View* v : views) result.images.push_back(evaluate_view(e, *v, result));
    result.gt_mask = e.every_gt_mask;
    score_albedo(e.albedo_inputs, result);
    summarize_normals(std::move(e.pooled_angles), result);
    summarize_views(result);
    if (!options.keep_panels)
        for (GtEnvImageResult& r : result.images) r.panels = SheetPanels{};
    return result;
}

}  // namespace lumigauss
