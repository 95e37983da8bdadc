#include "lumigauss/eval/holdout.h"

#include <algorithm>
#include <chrono>
#include <limits>

#include "lumigauss/relight/relit_render.h"
#include "lumigauss/render/raster_maps.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
    return 1e3 * std::chrono::duration<double>(Clock::now() - t0).count();
}

// Zeroes the columns outside [x0, x1).
Image keep_columns(Image mask, int x0, int x1) {
    for (int y = 0; y < mask.height; ++y)
        for (int x = 0; x < mask.width; ++x)
            if (x < x0 || x >= x1) mask.at(x, y, 0) = 0.0f;
    return mask;
}

Image mask_or_ones(const Image& scene_mask, int width, int height) {
    if (scene_mask.empty()) return Image(width, height, 1, 1.0f);
    if (scene_mask.width != width || scene_mask.height != height || scene_mask.channels != 1)
        throw Error("holdout: the mask is not one channel of the image's size");
    return scene_mask;
}

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

void add_metrics(ImageMetrics& sum, const ImageMetrics& m) {
    sum.psnr += m.psnr, sum.ssim += m.ssim, sum.mse += m.mse, sum.mae += m.mae;
}

void divide_metrics(ImageMetrics& m, double n) {
    m.psnr /= n, m.ssim /= n, m.mse /= n, m.mae /= n;
}

HoldoutImageResult evaluate_view(const TrainedRun& run, const Dataset& scene, const View& view,
                                 RelitRenderer& renderer, const HoldoutOptions& options) {
    HoldoutImageResult r;
    r.name = view.name;
    const int w = view.camera.width, h = view.camera.height;
    SheetPanels& p = r.panels;
    p.truth = scene.load_image(view);
    const Image scene_mask = scene.load_mask(view);
    const Image fit_mask = holdout_fit_mask(scene_mask, w, h);
    p.mask = holdout_score_mask(scene_mask, w, h, scene.load_sky_mask(view));
    r.fit_pixels = mask_pixels(fit_mask);
    r.score_pixels = mask_pixels(p.mask);
    if (r.fit_pixels == 0) throw Error(view.image_path + ": holdout: the left half has no pixel to fit");
    if (r.score_pixels == 0)
        throw Error(view.image_path + ": holdout: the right half has no fully covered pixel to score" +
                    (view.sky_mask_path.empty() ? "" : " outside the sky mask " + view.sky_mask_path));

    auto t0 = Clock::now();
    LightFitOptions fit_options = options.fit;
    fit_options.shadowed = true;
    const LightFitResult fit = fit_light(run, view.camera, p.truth, fit_mask, fit_options);
    r.fit_psnr = fit.final_psnr;
    r.light = fit.sh;
    LightFitResult fit_unshadowed;
    if (options.unshadowed) {
        fit_options.shadowed = false;
        fit_unshadowed = fit_light(run, view.camera, p.truth, fit_mask, fit_options);
        r.fit_psnr_unshadowed = fit_unshadowed.final_psnr;
        r.light_unshadowed = fit_unshadowed.sh;
    }
    r.fit_ms = ms_since(t0) / (options.unshadowed ? 2 : 1);

    // The unshadowed colour under its own light first; then everything else under the shadowed fit.
    // Each drawn as the fit saw it: over its fitted sky when the run was trained with its sky behind.
    if (options.unshadowed) {
        p.unshadowed =
            fitted_colour(run, view.camera, renderer.render(view.camera, r.light_unshadowed.cast<float>()),
                          kRelitUnshadowed, fit_unshadowed);
        r.unshadowed = image_metrics(p.unshadowed, p.truth, p.mask, options.ssim);
    } else {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        r.fit_psnr_unshadowed = nan;
        r.unshadowed = {nan, nan, nan, nan};
    }
    t0 = Clock::now();
    const RasterImages<float>& relit = renderer.render(view.camera, fit.sh.cast<float>());
    r.render_ms = ms_since(t0);
    p.shadowed = fitted_colour(run, view.camera, relit, kRelitShadowed, fit);
    r.shadowed = image_metrics(p.shadowed, p.truth, p.mask, options.ssim);
    if (options.keep_panels) {
        p.albedo = clamp01(raster_channels(relit, kRelitAlbedo, 3));
        p.normal = encode_normals(relit);
        p.shadow = shadow_image(raster_channels(relit, kRelitIntensityUnshadowed, 3),
                                raster_channels(relit, kRelitIntensityShadowed, 3));
    } else {
        p = SheetPanels{};
    }
    return r;
}

}  // namespace

Image holdout_fit_mask(const Image& scene_mask, int width, int height) {
    return keep_columns(mask_or_ones(scene_mask, width, height), 0, width / 2);
}

Image holdout_score_mask(const Image& scene_mask, int width, int height, const Image& sky_mask) {
    Image binary = binarize_mask(mask_or_ones(scene_mask, width, height), 0.5f);
    if (!sky_mask.empty()) {
        if (sky_mask.width != width || sky_mask.height != height || sky_mask.channels != 1)
            throw Error("holdout: the sky mask is not one channel of the image's size");
        for (std::size_t p = 0; p < binary.pixels.size(); ++p)
            if (sky_mask.pixels[p] >= 0.5f) binary.pixels[p] = 0.0f;
    }
    return keep_columns(official_eval_mask(binary), width / 2, width);
}

HoldoutResult evaluate_holdout(const TrainedRun& run, const Dataset& scene, const HoldoutOptions& options) {
    HoldoutResult result;
    result.variable = options.fit.variable;
    result.iterations = options.fit.iterations;
    result.views = options.views;
    const std::vector<const View*> all = scene.split(options.views);
    if (all.empty())
        throw Error(scene.root + ": the scene has no " + split_name(options.views) + " image to evaluate");
    // At most max_views, spread evenly over the split (the first always among them).
    std::vector<const View*> views;
    const std::size_t count = options.max_views > 0 ? std::min(options.max_views, all.size()) : all.size();
    for (std::size_t i = 0; i < count; ++i) views.push_back(all[i * all.size() / count]);
    RelitRenderer renderer(run.model, options.backend, run.side_rule);
    std::vector<double> fit_ms, render_ms;
    for (const View* v : views) {
        result.images.push_back(evaluate_view(run, scene, *v, renderer, options));
        if (options.on_image) options.on_image(result.images.back(), result.images.size(), views.size());
        const HoldoutImageResult& r = result.images.back();
        add_metrics(result.mean_shadowed, r.shadowed);
        add_metrics(result.mean_unshadowed, r.unshadowed);
        result.mean_fit_psnr += r.fit_psnr;
        result.mean_fit_psnr_unshadowed += r.fit_psnr_unshadowed;
        fit_ms.push_back(r.fit_ms), render_ms.push_back(r.render_ms);
    }
    const double n = double(result.images.size());
    divide_metrics(result.mean_shadowed, n);
    divide_metrics(result.mean_unshadowed, n);
    result.mean_fit_psnr /= n;
    result.mean_fit_psnr_unshadowed /= n;
    result.median_fit_ms = median(fit_ms);
    result.median_render_ms = median(render_ms);
    return result;
}

}  // namespace lumigauss
