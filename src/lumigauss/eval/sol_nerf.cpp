#include "lumigauss/eval/sol_nerf.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <numbers>

#include "lumigauss/eval/multi_light_render.h"
#include "lumigauss/eval/official_sh_projection.h"
#include "lumigauss/eval/official_sh_rotation.h"
#include "lumigauss/eval/opencv_resize.h"
#include "lumigauss/relight/relit_render.h"
#include "lumigauss/render/raster_maps.h"
#include "lumigauss/shading/sh_rotation.h"
#include "lumigauss/util/error.h"
#include "lumigauss/util/text.h"

namespace lumigauss {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
    return 1e3 * std::chrono::duration<double>(Clock::now() - t0).count();
}

double radians(double degrees) {
    return degrees * std::numbers::pi / 180.0;
}

// The configured file, or an Error naming the first place looked at (and the others).
std::string resolve_or_fail(const std::string& configured, const std::string& root, const std::string& scene,
                            const std::string& what, const std::string& root_option) {
    std::vector<std::string> tried;
    if (auto found = resolve_sol_nerf_path(configured, root, scene, tried)) return *found;
    std::string also;
    for (std::size_t i = 1; i < tried.size(); ++i) also += (i > 1 ? ", " : "") + tried[i];
    fail_in_file(tried.front(), "missing (" + what + "; relative paths are resolved against " + root_option +
                                    ", by default the scene folder, then its final/ folder" +
                                    (also.empty() ? "" : "; also tried " + also) + ")");
}

// Step 4's mask: the configured evaluation mask, or the scene's own mask of the photo.
Image evaluation_mask(const Dataset& scene, const View& view, const std::string& mask_path) {
    const int w = view.camera.width, h = view.camera.height;
    if (mask_path.empty()) return official_eval_mask(scene.load_mask(view));
    return sol_nerf_eval_mask(to_channels(read_image(mask_path), 1), w, h);
}

// Step 3: the masked PSNR of the clamped shadowed render at every angle, several angles per rasterisation.
void search_angle(MultiLightRenderer& renderer, const View& view, const Image& photo, const Image& mask,
                  SolNerfImageResult& r) {
    const auto t0 = Clock::now();
    std::vector<ShCoeffs<float>> envs;
    for (double b : r.angles) envs.push_back(sol_nerf_environment(r.projected_sh, r.config, b).cast<float>());
    const std::vector<Image> renders = renderer.render_shadowed(view.camera, envs);
    for (const Image& render : renders)
        r.search_psnr.push_back(psnr_from_mse(masked_mse(clamp01(render), photo, mask)));
    r.best_index = first_best_index(r.search_psnr);
    r.best_angle = r.angles[r.best_index];
    r.world_sh = sol_nerf_environment(r.projected_sh, r.config, r.best_angle);
    r.search_ms = ms_since(t0);
}

// Step 4: both renders and the maps of the contact sheet at the chosen angle, and their metrics.
void score_best_angle(RelitRenderer& renderer, const View& view, const SsimOptions& ssim,
                      SolNerfImageResult& r) {
    const auto t0 = Clock::now();
    const RasterImages<float>& relit = renderer.render(view.camera, r.world_sh.cast<float>());
    r.render_ms = ms_since(t0);
    SheetPanels& p = r.panels;
    p.shadowed = clamp01(raster_channels(relit, kRelitShadowed, 3));
    p.unshadowed = clamp01(raster_channels(relit, kRelitUnshadowed, 3));
    r.shadowed = image_metrics(p.shadowed, p.truth, p.mask, ssim);
    r.unshadowed = image_metrics(p.unshadowed, p.truth, p.mask, ssim);
    p.albedo = clamp01(raster_channels(relit, kRelitAlbedo, 3));
    p.normal = encode_normals(relit);
    p.shadow = shadow_image(raster_channels(relit, kRelitIntensityUnshadowed, 3),
                            raster_channels(relit, kRelitIntensityShadowed, 3));
}

SolNerfImageResult evaluate_image(const SolNerfImageConfig& image, const Dataset& scene,
                                  const SolNerfConfig& config, const SolNerfOptions& options,
                                  MultiLightRenderer& search, RelitRenderer& final_render) {
    SolNerfImageResult r;
    r.config = image;
    const View* view = find_sol_nerf_view(scene, image.name);
    if (!view)
        fail_in_file(config.path, "test image \"" + image.name + "\" is not in the scene " + scene.root +
                                      " (neither that name nor its stem with another extension)");
    r.view_name = view->name;
    r.split = view->split;
    r.env_map_path =
        resolve_or_fail(image.env_map, options.roots.env_root, options.roots.scene,
                        "the environment map of " + image.name + " in " + config.path, "--env-root");
    if (!image.mask.empty())
        r.mask_path =
            resolve_or_fail(image.mask, options.roots.mask_root, options.roots.scene,
                            "the evaluation mask of " + image.name + " in " + config.path, "--mask-root");
    const OfficialEnvironment env =
        official_environment_sh(r.env_map_path, image.hdr_threshold, image.hdr_scale);
    r.projected_sh = env.sh;
    r.boosted_values = env.boosted;

    SheetPanels& p = r.panels;
    p.truth = scene.load_image(*view);
    p.mask = evaluation_mask(scene, *view, r.mask_path);
    r.mask_pixels = mask_pixels(p.mask);
    if (r.mask_pixels == 0)
        fail_in_file(!r.mask_path.empty()       ? r.mask_path
                     : !view->mask_path.empty() ? view->mask_path
                                                : view->image_path,
                     "the evaluation mask is empty (no fully covered pixel after the 5x5 erosion)");

    r.angles = sol_nerf_angles(image.y_min, image.y_max, options.angles > 0 ? options.angles : config.angles);
    search_angle(search, *view, p.truth, p.mask, r);
    score_best_angle(final_render, *view, options.ssim, r);
    return r;
}

void add_mean(ImageMetrics& sum, const ImageMetrics& m, double n) {
    sum.psnr += m.psnr / n, sum.ssim += m.ssim / n, sum.mse += m.mse / n, sum.mae += m.mae / n;
}

}  // namespace

std::vector<double> sol_nerf_angles(double first, double last, int n) {
    if (n < 1) throw Error("the number of search angles must be at least 1");
    std::vector<double> a(std::size_t(n), first);
    // torch.linspace fills the first half from `first` and the second half from `last` with one step.
    if (n == 1) return a;
    const double step = (last - first) / (n - 1);
    for (int i = 0; i < n; ++i) a[std::size_t(i)] = i < n / 2 ? first + step * i : last - step * (n - 1 - i);
    return a;
}

ShCoeffs<double> sol_nerf_environment(const ShCoeffs<double>& projected, const SolNerfImageConfig& image,
                                      double b) {
    const Mat3d r = official_environment_rotation(
        radians(image.rotation_deg[0]), radians(image.rotation_deg[1]), radians(image.rotation_deg[2]), b);
    return rotate_sh(projected, r);
}

Image sol_nerf_eval_mask(const Image& gray, int width, int height) {
    const Image one = to_channels(gray, 1);
    return official_eval_mask(
        one.width == width && one.height == height ? one : resize_linear_opencv(one, width, height));
}

std::size_t first_best_index(const std::vector<double>& values) {
    if (values.empty()) throw Error("no search value to choose from");
    std::size_t best = 0;
    for (std::size_t i = 0; i < values.size(); ++i)
        if (values[i] > values[best] || (std::isnan(values[best]) && !std::isnan(values[i]))) best = i;
    return best;
}

const View* find_sol_nerf_view(const Dataset& scene, const std::string& name) {
    for (const View& v : scene.views)
        if (v.name == name) return &v;
    const View* found = nullptr;
    for (const View& v : scene.views)
        if (without_extension(v.name) == without_extension(name)) {
            if (found) return nullptr;
            found = &v;
        }
    return found;
}

SolNerfResult evaluate_sol_nerf(const SurfelModel& model, const Dataset& scene, const SolNerfConfig& config,
                                const SolNerfOptions& options) {
    SolNerfResult result;
    result.config_path = config.path;
    result.downscale = scene.downscale;
    result.angles = options.angles > 0 ? options.angles : config.angles;
    MultiLightRenderer search(model, options.backend, options.sides);
    RelitRenderer final_render(model, options.backend, options.sides);
    for (const SolNerfImageConfig& image : config.images) {
        result.images.push_back(evaluate_image(image, scene, config, options, search, final_render));
        result.search_seconds += result.images.back().search_ms / 1e3;
        if (!options.keep_panels) result.images.back().panels = SheetPanels{};
    }
    const double n = double(result.images.size());
    std::vector<double> render_ms;
    for (const SolNerfImageResult& r : result.images) {
        add_mean(result.mean_shadowed, r.shadowed, n);
        add_mean(result.mean_unshadowed, r.unshadowed, n);
        render_ms.push_back(r.render_ms);
    }
    if (!render_ms.empty()) {
        std::sort(render_ms.begin(), render_ms.end());
        result.median_render_ms = render_ms[render_ms.size() / 2];
    }
    return result;
}

}  // namespace lumigauss
