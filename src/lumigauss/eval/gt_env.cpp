#include "lumigauss/eval/gt_env.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>

#include "lumigauss/io/text_file.h"
#include "lumigauss/math/quaternion.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/relight/relit_render.h"
#include "lumigauss/relight/relit_sky.h"
#include "lumigauss/render/raster_maps.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/sh_text.h"
#include "lumigauss/shading/sky_image.h"
#include "lumigauss/shading/surfel_shading.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

constexpr double kGamma = 1.0 / surfel_const::kInvGamma;  // 2.2, the model's light-to-colour exponent

Json parse_json_file(const std::string& path) {
    Json j = Json::parse(read_text_file(path), nullptr, false);
    if (j.is_discarded()) fail_in_file(path, "not valid JSON");
    return j;
}

// <root>/gt/<kind>/<image name with a .png extension>.
std::string gt_path(const std::string& root, const std::string& kind, const std::string& image_name) {
    fs::path p = fs::path(root) / "gt" / kind / image_name;
    p.replace_extension(".png");
    return p.string();
}

// A ground-truth image with `channels` channels at width x height (area-resampled if the file differs).
Image load_gt_image(const std::string& path, int width, int height, int channels) {
    Image im = to_channels(read_image(path), channels);
    if (im.width != width || im.height != height) im = resize_area(im, width, height);
    return im;
}

Image multiply_masks(const Image& a, const Image& b) {
    Image out = a;
    for (std::size_t p = 0; p < out.pixels.size(); ++p) out.pixels[p] *= b.pixels[p];
    return out;
}

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

// The evaluation mask of a view (header, step 3), and whether the scene has a gt/mask for it.
Image evaluation_mask(const GtSceneMeta& meta, const Dataset& scene, const View& v, bool& has_gt_mask) {
    const std::string gt_mask_path = gt_path(meta.root, "mask", v.name);
    has_gt_mask = fs::exists(gt_mask_path);
    const Image scene_mask = binarize_mask(scene.load_mask(v), 0.5f);
    return has_gt_mask
               ? multiply_masks(
                     official_eval_mask(load_gt_image(gt_mask_path, v.camera.width, v.camera.height, 1)),
                     scene_mask)
               : official_eval_mask(scene_mask);
}

// The environment of a view: scale_c * exposure * (true SH of its condition), per channel.
ShCoeffs<float> scaled_true_env(const GtSceneMeta& meta, const GtImageMeta& im,
                                const std::array<double, 3>& scale) {
    const ShCoeffs<double> truth = load_condition_sh(meta, im.condition);
    ShCoeffs<float> env;
    for (int j = 0; j < kShCount; ++j)
        for (int c = 0; c < 3; ++c) env.c[j][c] = float(truth.c[j][c] * scale[std::size_t(c)] * im.exposure);
    return env;
}

// The conditions' panoramas (env/COND.exr or .hdr, the scene's ground truth), each read once.
class TruePanoramas {
  public:
    explicit TruePanoramas(const GtSceneMeta& meta) : meta_(meta) {}
    // nullptr when the scene has no panorama of the condition.
    const Image* find(const std::string& condition) {
        auto [it, added] = cache_.try_emplace(condition);
        if (added)
            for (const char* ext : {".exr", ".hdr"})
                if (const std::string path = meta_.root + "/env/" + condition + ext; fs::exists(path)) {
                    it->second = read_image(path);
                    break;
                }
        return it->second ? &*it->second : nullptr;
    }

  private:
    const GtSceneMeta& meta_;
    std::map<std::string, std::optional<Image>> cache_;
};

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
    Image truth;     // gt/albedo, linear
};

}  // namespace

// ---- Scene ground truth -------------------------------------------------------------------------------

const GtImageMeta* GtSceneMeta::find(const std::string& name) const {
    for (const GtImageMeta& m : images)
        if (m.name == name) return &m;
    return nullptr;
}

std::string GtSceneMeta::sh_path(const std::string& condition) const {
    const auto it = condition_sh.find(condition);
    if (it != condition_sh.end()) return (fs::path(root) / it->second).string();
    return (fs::path(root) / "env" / (condition + "_sh.txt")).string();
}

GtSceneMeta load_gt_scene_meta(const std::string& scene_root) {
    GtSceneMeta meta;
    meta.root = scene_root;
    meta.meta_path = (fs::path(scene_root) / "meta.json").string();
    if (!fs::exists(meta.meta_path))
        fail_in_file(meta.meta_path,
                     "missing: the gt-env protocol needs a scene with ground-truth lighting (meta.json, "
                     "env/COND_sh.txt), as data/plaza or `lumigauss synth` write");
    const Json j = parse_json_file(meta.meta_path);
    if (!j.is_object() || !j.contains("images") || !j["images"].is_array())
        fail_in_file(meta.meta_path, "expected a JSON object with an \"images\" array");
    std::size_t index = 0;
    for (const Json& e : j["images"]) {
        const std::string where = "images[" + std::to_string(index++) + "]";
        if (!e.is_object() || !e.contains("name") || !e["name"].is_string() || !e.contains("condition") ||
            !e["condition"].is_string())
            fail_in_file(meta.meta_path, where + " needs a string \"name\" and a string \"condition\"");
        GtImageMeta m;
        m.name = e["name"].get<std::string>();
        m.condition = e["condition"].get<std::string>();
        if (e.contains("split")) {
            if (!e["split"].is_string()) fail_in_file(meta.meta_path, where + ": \"split\" must be a string");
            m.split = e["split"].get<std::string>();
        }
        if (e.contains("exposure")) {
            if (!e["exposure"].is_number() || !(e["exposure"].get<double>() > 0))
                fail_in_file(meta.meta_path, where + ": \"exposure\" must be a positive number");
            m.exposure = e["exposure"].get<double>();
        }
        meta.images.push_back(std::move(m));
    }
    if (j.contains("conditions") && j["conditions"].is_array())
        for (const Json& c : j["conditions"])
            if (c.is_object() && c.contains("id") && c["id"].is_string() && c.contains("sh") &&
                c["sh"].is_string())
                meta.condition_sh[c["id"].get<std::string>()] = c["sh"].get<std::string>();
    return meta;
}

ShCoeffs<double> load_condition_sh(const GtSceneMeta& meta, const std::string& condition) {
    const std::string path = meta.sh_path(condition);
    if (!fs::exists(path))
        fail_in_file(path, "missing: the true SH of lighting condition '" + condition + "' (named in " +
                               meta.meta_path + ")");
    return read_sh_text(path);
}

// ---- Run ----------------------------------------------------------------------------------------------

RelightableRun load_relightable_run(const std::string& path) {
    TrainedRun trained = load_run_or_ply(path);
    RelightableRun run;
    run.dir = trained.dir;
    run.model = std::move(trained.model);
    run.image_names = std::move(trained.image_names);
    for (int i = 0; i < trained.lighting.num_images(); ++i) run.learned_sh.push_back(trained.learned_sh(i));
    run.downscale = trained.downscale;
    run.sky_background = trained.sky_background;
    run.sky_horizon = trained.sky_horizon;
    return run;
}

SurfelModel relightable_from_surfels(const ViewDependentSurfels& s) {
    const std::size_t n = s.size();
    const std::size_t coeffs = std::size_t((s.sh_degree + 1) * (s.sh_degree + 1));
    if (s.sh.size() != n * coeffs * 3) throw Error("relightable_from_surfels: SH array of the wrong size");
    std::vector<std::vector<float>> raw(kModelParamCount);
    raw[int(ModelParam::Xyz)] = s.surfels.means;
    raw[int(ModelParam::Rotation)] = s.surfels.quats;
    for (float v : s.surfels.scales) raw[int(ModelParam::Scaling)].push_back(std::log(std::max(v, 1e-12f)));
    for (float v : s.surfels.opacities)
        raw[int(ModelParam::Opacity)].push_back(inverse_sigmoid(std::clamp(v, 1e-6f, 1.0f - 1e-6f)));
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t c = 0; c < 3; ++c) {
            const double rho = std::max(0.0, 0.5 + sh_const::kY00 * double(s.sh[i * coeffs * 3 + c]));
            const double target = std::pow(rho / std::numbers::pi, 1.0 / kGamma);
            raw[int(ModelParam::Albedo)].push_back(float((target - 0.5) / sh_const::kY00));
        }
        const Vec4f q = normalize_quaternion(Vec4f{s.surfels.quats[4 * i], s.surfels.quats[4 * i + 1],
                                                   s.surfels.quats[4 * i + 2], s.surfels.quats[4 * i + 3]});
        const Mat3f r = rotation_from_unit_quaternion(q);
        const Vec3f axis{r.m[0][2], r.m[1][2], r.m[2][2]};
        float pos[kShCount], neg[kShCount];
        cosine_lobe_sh(axis, pos);
        cosine_lobe_sh(-axis, neg);
        for (int k = 0; k < kShCount; ++k)
            for (int c = 0; c < 3; ++c) {
                raw[int(ModelParam::TransferPositive)].push_back(pos[k]);
                raw[int(ModelParam::TransferNegative)].push_back(neg[k]);
            }
    }
    return SurfelModel::from_raw(std::move(raw));
}

// ---- Light scale ----------------------------------------------------------------------------------------

double irradiance_weight(int j) {
    const double a = j == 0 ? rh_const::kA0 : (j < 4 ? rh_const::kA1 : rh_const::kA2);
    return a * a;
}

LightScaleFit fit_light_scale(const std::vector<ShCoeffs<double>>& learned,
                              const std::vector<ShCoeffs<double>>& truth, const std::vector<double>& exposure,
                              const std::vector<std::string>& names) {
    if (learned.empty()) throw Error("light scale: no training photo to fit it on");
    if (learned.size() != truth.size() || learned.size() != exposure.size() ||
        (!names.empty() && names.size() != learned.size()))
        throw Error("light scale: the lists of learned SH, true SH and exposures differ in length");
    LightScaleFit fit;
    fit.names = names;
    double lt = 0, tt = 0, ll = 0;
    for (std::size_t i = 0; i < learned.size(); ++i) {
        double lt_i = 0, tt_i = 0;
        for (int j = 0; j < kShCount; ++j) {
            const double w = irradiance_weight(j);
            for (int c = 0; c < 3; ++c) {
                const double l = learned[i].c[j][c], t = truth[i].c[j][c];
                lt_i += w * l * t, tt_i += w * t * t, ll += w * l * l;
            }
        }
        const double e = exposure[i];
        lt += e * lt_i, tt += e * e * tt_i;
        fit.per_photo.push_back(tt_i > 0 ? lt_i / (e * tt_i) : std::numeric_limits<double>::quiet_NaN());
    }
    if (!(tt > 0)) throw Error("light scale: the true lighting of every training photo is zero");
    fit.scale = lt / tt;
    // sum w |L - k e T|^2 = ll - 2 k lt + k^2 tt, at the optimum ll - k lt.
    const double residual = std::max(0.0, ll - fit.scale * lt);
    fit.relative_residual = ll > 0 ? std::sqrt(residual / ll) : 0.0;
    return fit;
}

LightScaleFit fit_run_light_scale(const RelightableRun& run, const GtSceneMeta& meta,
                                  const std::vector<std::string>& exclude) {
    if (run.image_names.empty()) return {};  // a bare PLY: no learned light to scale
    std::vector<ShCoeffs<double>> learned, truth;
    std::vector<double> exposure;
    std::vector<std::string> names;
    for (std::size_t i = 0; i < run.image_names.size(); ++i) {
        const GtImageMeta* m = meta.find(run.image_names[i]);
        if (!m || m->split != "train") continue;  // never fit on a test photo
        if (std::find(exclude.begin(), exclude.end(), m->name) != exclude.end()) continue;
        learned.push_back(run.learned_sh[i]);
        truth.push_back(load_condition_sh(meta, m->condition));
        exposure.push_back(m->exposure);
        names.push_back(m->name);
    }
    if (learned.empty())
        fail_in_file(meta.meta_path, "none of the run's " + std::to_string(run.image_names.size()) +
                                         " training photos is listed with split \"train\"");
    return fit_light_scale(learned, truth, exposure, names);
}

std::optional<std::array<double, 3>> fit_image_light_scale(const RelightableRun& run, const Dataset& scene,
                                                           const GtSceneMeta& meta,
                                                           const std::vector<std::string>& exclude,
                                                           RasterBackend backend) {
    RelitRenderer renderer(run.model, backend);
    std::array<double, 3> rp{}, rr{};
    for (const View* v : scene.split(Split::Train)) {
        const GtImageMeta* im = meta.find(v->name);
        if (im == nullptr || std::find(exclude.begin(), exclude.end(), v->name) != exclude.end()) continue;
        const RasterImages<float>& relit = renderer.render(v->camera, scaled_true_env(meta, *im, {1, 1, 1}));
        const Image photo = scene.load_image(*v);
        bool has_gt_mask = false;
        const Image mask = evaluation_mask(meta, scene, *v, has_gt_mask);
        for (std::size_t q = 0; q < mask.pixels.size(); ++q) {
            if (!(mask.pixels[q] > 0.5f) || relit.alpha[q] <= 0.5f) continue;
            const std::size_t i = 3 * q, o = std::size_t(relit.channels) * q + kRelitShadowed;
            // A clipped photo pixel says only "at least 1": it would pull the scale down.
            if (std::max({photo.pixels[i], photo.pixels[i + 1], photo.pixels[i + 2]}) >= 0.99f) continue;
            for (std::size_t c = 0; c < 3; ++c) {
                const double r = relit.color[o + c], p = photo.pixels[i + c];
                if (!std::isfinite(r)) continue;
                rp[c] += r * p, rr[c] += r * r;
            }
        }
    }
    std::array<double, 3> k{1, 1, 1};
    for (std::size_t c = 0; c < 3; ++c) {
        if (!(rr[c] > 0 && rp[c] > 0)) return std::nullopt;
        k[c] = std::pow(rp[c] / rr[c], 1.0 / surfel_const::kInvGamma);  // display colour goes as E^(1/2.2)
    }
    return k;
}

// ---- Protocol -------------------------------------------------------------------------------------------

GtEnvResult evaluate_gt_env(const RelightableRun& run, const Dataset& scene, const GtSceneMeta& meta,
                            const GtEnvOptions& options) {
    GtEnvResult result;
    result.downscale = scene.downscale;
    result.views = options.views;
    const std::vector<const View*> views = scene.split(options.views);
    if (views.empty())
        throw Error(scene.root + ": the scene has no " + split_name(options.views) + " image to evaluate");
    std::vector<std::string> test_names;  // excluded from the light-scale fit
    if (options.views != Split::Train)
        for (const View* v : views) test_names.push_back(v->name);
    result.light = fit_run_light_scale(run, meta, test_names);
    if (options.image_light_scale)
        if (const auto k = fit_image_light_scale(run, scene, meta, test_names, options.backend)) {
            result.image_scaled = true;
            result.image_light_scale = *k;
        }

    // One pass per view gives both colours, both intensities and the albedo (relight/relit_render.h).
    RelitRenderer renderer(run.model, options.backend);
    TruePanoramas panoramas(meta);

    std::vector<AlbedoInputs> albedo_inputs;
    std::vector<double> pooled_angles;
    bool any_albedo = false, all_albedo = true, any_normal = false;
    for (const View* v : views) {
        const GtImageMeta* im = meta.find(v->name);
        if (!im) fail_in_file(meta.meta_path, "no entry for test image '" + v->name + "'");
        GtEnvImageResult r;
        r.name = v->name;
        r.condition = im->condition;
        r.exposure = im->exposure;
        const int w = v->camera.width, h = v->camera.height;

        // Render under k * exposure * true SH.
        const ShCoeffs<double> truth = load_condition_sh(meta, im->condition);
        ShCoeffs<float> env;
        for (int j = 0; j < kShCount; ++j)
            env.c[j] = (truth.c[j] * (result.light.scale * im->exposure)).cast<float>();
        const auto t0 = std::chrono::steady_clock::now();
        const RasterImages<float>& relit = renderer.render(v->camera, env);
        r.render_ms = 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        GtEnvPanels& p = r.panels;
        p.shadowed = raster_channels(relit, kRelitShadowed, 3);
        p.unshadowed = raster_channels(relit, kRelitUnshadowed, 3);
        if (run.sky_background) {
            const double k = result.light.scale;
            const Image sky = true_sky_image(run, meta, panoramas, *im, v->camera, {k, k, k});
            const Image alpha = alpha_image(relit);
            p.shadowed = over_background_image(p.shadowed, alpha, sky);
            p.unshadowed = over_background_image(p.unshadowed, alpha, sky);
        }
        p.shadowed = clamp01(p.shadowed);
        p.unshadowed = clamp01(p.unshadowed);
        p.truth = scene.load_image(*v);

        // Evaluation mask.
        const std::string gt_mask_path = gt_path(meta.root, "mask", v->name);
        bool has_gt_mask = false;
        p.mask = evaluation_mask(meta, scene, *v, has_gt_mask);
        result.gt_mask = (result.images.empty() || result.gt_mask) && has_gt_mask;
        r.mask_pixels = mask_pixels(p.mask);
        if (r.mask_pixels == 0)
            fail_in_file(has_gt_mask ? gt_mask_path : v->image_path,
                         "the evaluation mask is empty (no fully covered pixel after the 5x5 erosion)");
        if (has_gt_mask) {
            const Image coverage = load_gt_image(gt_mask_path, w, h, 1);
            std::size_t covered = 0;
            for (std::size_t q = 0; q < coverage.pixels.size(); ++q) {
                if (coverage.pixels[q] != 0.0f) continue;
                ++r.sky_pixels;
                covered += relit.alpha[q] > 0.5f ? 1 : 0;
            }
            r.sky_alpha_fraction = r.sky_pixels > 0 ? double(covered) / double(r.sky_pixels) : 0.0;
        }
        r.shadowed = image_metrics(p.shadowed, p.truth, p.mask, options.ssim);
        r.unshadowed = image_metrics(p.unshadowed, p.truth, p.mask, options.ssim);
        Image covered_mask = p.mask;
        for (std::size_t q = 0; q < covered_mask.pixels.size(); ++q)
            if (relit.alpha[q] <= 0.5f) covered_mask.pixels[q] = 0.0f;
        const std::size_t covered_pixels = mask_pixels(covered_mask);
        r.empty_fraction = 1.0 - double(covered_pixels) / double(r.mask_pixels);
        r.covered_shadowed_psnr = covered_pixels > 0
                                      ? psnr_from_mse(masked_mse(p.shadowed, p.truth, covered_mask))
                                      : std::numeric_limits<double>::quiet_NaN();

        // The paper's shadow image (as `render` writes it) and the model's albedo and normal maps.
        p.shadow = shadow_image(raster_channels(relit, kRelitIntensityUnshadowed, 3),
                                raster_channels(relit, kRelitIntensityShadowed, 3));
        const Image rendered_albedo = raster_channels(relit, kRelitAlbedo, 3);
        Image rendered_normal(w, h, 3);
        rendered_normal.pixels = relit.normal;
        p.normal = encode_normals(relit);

        const std::string gt_albedo_path = gt_path(meta.root, "albedo", v->name);
        if (fs::exists(gt_albedo_path)) {
            r.has_albedo = any_albedo = true;
            AlbedoInputs in{rendered_albedo, load_gt_image(gt_albedo_path, w, h, 3)};
            p.gt_albedo = map_values(in.truth, to_gamma);
            albedo_inputs.push_back(std::move(in));
        } else {
            all_albedo = false;
            albedo_inputs.emplace_back();
        }

        const std::string gt_normal_path = gt_path(meta.root, "normal", v->name);
        if (fs::exists(gt_normal_path)) {
            r.has_normal = any_normal = true;
            p.gt_normal = load_gt_image(gt_normal_path, w, h, 3);
            Image decoded = p.gt_normal;
            for (float& x : decoded.pixels) x = 2.0f * x - 1.0f;
            r.normal = normal_angular_error(rendered_normal, decoded, p.mask, 1e-3, &pooled_angles);
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
        // The same view under the image-space light scale (a second render: the sky and the clamp follow it).
        if (result.image_scaled)
            r.image_scaled_shadowed = image_metrics(
                shadowed_panel(run, meta, panoramas, *im, renderer, v->camera, result.image_light_scale),
                p.truth, p.mask, options.ssim);
        result.images.push_back(std::move(r));
    }

    // Albedo: one per-channel scale per domain, pooled over every test image with a ground truth.
    result.has_albedo = any_albedo && all_albedo;
    if (result.has_albedo) {
        ScaleFitTerms lin_terms, gam_terms;
        std::vector<Image> lin_pred, gam_pred, lin_truth, gam_truth;
        for (std::size_t i = 0; i < albedo_inputs.size(); ++i) {
            const Image& mask = result.images[i].panels.mask;
            lin_pred.push_back(map_values(albedo_inputs[i].rendered, to_linear));
            gam_pred.push_back(
                map_values(albedo_inputs[i].rendered, [](double x) { return std::max(x, 0.0); }));
            lin_truth.push_back(albedo_inputs[i].truth);
            gam_truth.push_back(map_values(albedo_inputs[i].truth, to_gamma));
            add_scale_terms(lin_pred[i], lin_truth[i], mask, lin_terms);
            add_scale_terms(gam_pred[i], gam_truth[i], mask, gam_terms);
        }
        const std::array<double, 4> lin_scale = scale_from_terms(lin_terms),
                                    gam_scale = scale_from_terms(gam_terms);
        for (int c = 0; c < 3; ++c)
            result.albedo_scale[c] = lin_scale[c], result.albedo_gamma_scale[c] = gam_scale[c];
        for (std::size_t i = 0; i < albedo_inputs.size(); ++i) {
            GtEnvImageResult& r = result.images[i];
            const Image lin = clamp01(scale_channels(lin_pred[i], lin_scale));
            const Image gam = clamp01(scale_channels(gam_pred[i], gam_scale));
            r.albedo = albedo_metrics(lin, lin_truth[i], r.panels.mask);
            r.albedo_gamma = albedo_metrics(gam, gam_truth[i], r.panels.mask);
            r.panels.albedo = gam;
        }
    } else {
        for (GtEnvImageResult& r : result.images) {
            r.has_albedo = false;
            r.panels.gt_albedo = Image();
        }
    }

    // Means over images.
    const double n = double(result.images.size());
    auto add_metrics = [n](ImageMetrics& sum, const ImageMetrics& m) {
        sum.psnr += m.psnr / n, sum.ssim += m.ssim / n, sum.mse += m.mse / n, sum.mae += m.mae / n;
    };
    auto add_albedo = [n](AlbedoMetrics& sum, const AlbedoMetrics& m) {
        sum.psnr += m.psnr / n, sum.mse += m.mse / n, sum.mae += m.mae / n;
    };
    std::size_t normal_images = 0;
    for (const GtEnvImageResult& r : result.images) {
        add_metrics(result.mean_shadowed, r.shadowed);
        add_metrics(result.mean_image_scaled_shadowed, r.image_scaled_shadowed);
        add_metrics(result.mean_unshadowed, r.unshadowed);
        if (result.has_albedo)
            add_albedo(result.mean_albedo, r.albedo), add_albedo(result.mean_albedo_gamma, r.albedo_gamma);
        if (r.has_normal && r.normal.pixels > 0) {
            ++normal_images;
            result.mean_normal.mean_deg += r.normal.mean_deg;
            result.mean_normal.median_deg += r.normal.median_deg;
            result.mean_normal.pixels += r.normal.pixels;
            result.mean_normal.missing += r.normal.missing;
        }
    }
    result.has_normal = any_normal && normal_images == result.images.size();
    if (result.has_normal) {
        result.mean_normal.mean_deg /= double(normal_images);
        result.mean_normal.median_deg /= double(normal_images);
        std::size_t missing = 0;
        for (const GtEnvImageResult& r : result.images) missing += r.normal.missing;
        result.pooled_normal = angle_stats(std::move(pooled_angles));
        result.pooled_normal.missing = missing;
    }
    std::size_t sky_pixels = 0;
    double sky_covered = 0;
    for (const GtEnvImageResult& r : result.images)
        sky_pixels += r.sky_pixels, sky_covered += r.sky_alpha_fraction * double(r.sky_pixels);
    std::size_t evaluated = 0, covered_images = 0;
    double empty = 0;
    for (const GtEnvImageResult& r : result.images) {
        evaluated += r.mask_pixels, empty += r.empty_fraction * double(r.mask_pixels);
        if (!std::isnan(r.covered_shadowed_psnr))
            result.mean_covered_shadowed_psnr += r.covered_shadowed_psnr, ++covered_images;
    }
    result.empty_fraction = evaluated > 0 ? empty / double(evaluated) : 0.0;
    result.mean_covered_shadowed_psnr = covered_images > 0
                                            ? result.mean_covered_shadowed_psnr / double(covered_images)
                                            : std::numeric_limits<double>::quiet_NaN();
    result.has_sky = sky_pixels > 0;
    result.sky_behind = run.sky_background;
    result.sky_horizon = run.sky_horizon;
    result.sky_alpha_fraction = result.has_sky ? sky_covered / double(sky_pixels) : 0.0;
    std::vector<double> render_ms;
    for (const GtEnvImageResult& r : result.images) render_ms.push_back(r.render_ms);
    if (!render_ms.empty()) {
        std::sort(render_ms.begin(), render_ms.end());
        result.median_render_ms = render_ms[render_ms.size() / 2];
    }
    if (!options.keep_panels)
        for (GtEnvImageResult& r : result.images) r.panels = GtEnvPanels{};
    return result;
}

}  // namespace lumigauss
