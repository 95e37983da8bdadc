#include "lumigauss/eval/report.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/io/image.h"
#include "lumigauss/shading/sh_text.h"

namespace lumigauss {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

Json number(double v) {
    return std::isfinite(v) ? Json(v) : Json(nullptr);
}

Json albedo_json(const AlbedoMetrics& m) {
    return Json{{"psnr", number(m.psnr)}, {"mse", number(m.mse)}, {"mae", number(m.mae)}};
}

Json normal_json(const AngularErrorStats& s, bool with_counts = true) {
    Json j{{"mean_deg", number(s.mean_deg)}, {"median_deg", number(s.median_deg)}};
    if (with_counts) j["pixels"] = s.pixels, j["missing"] = s.missing;
    return j;
}

Json rgb_json(const std::array<double, 3>& v) {
    return Json::array({number(v[0]), number(v[1]), number(v[2])});
}

std::string fmt(const char* f, double v) {
    if (!std::isfinite(v)) return "n/a";
    char buf[64];
    std::snprintf(buf, sizeof buf, f, v);
    return buf;
}

void paste(Image& sheet, const Image& panel, int x0, int y0, int w, int h, double gain = 1.0) {
    if (panel.empty() || panel.width != w || panel.height != h) return;  // left black
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) {
                const float v = panel.at(x, y, panel.channels == 1 ? 0 : c);
                sheet.at(x0 + x, y0 + y, c) = float(std::min(1.0, std::max(0.0, gain * double(v))));
            }
}

Image abs_difference(const Image& a, const Image& b) {
    if (a.empty() || b.empty() || a.pixels.size() != b.pixels.size()) return {};
    Image d = a;
    for (std::size_t i = 0; i < d.pixels.size(); ++i) d.pixels[i] = std::abs(a.pixels[i] - b.pixels[i]);
    return d;
}

}  // namespace

// ---- Shared by the protocols -----------------------------------------------------------------------------

std::string sheet_relative_path(const std::string& image_name) {
    fs::path p = fs::path("sheets") / image_name;
    p.replace_extension(".png");
    return p.generic_string();
}

std::string sh_file_relative_path(const std::string& image_name) {
    fs::path p = fs::path("env") / image_name;
    p.replace_extension();
    return p.generic_string() + "_sh.txt";
}

void write_scored_lights(const std::string& dir,
                         const std::vector<std::pair<std::string, ShCoeffs<double>>>& lights) {
    for (const auto& [name, sh] : lights) {
        const fs::path path = fs::path(dir) / sh_file_relative_path(name);
        fs::create_directories(path.parent_path());
        write_sh_text(path.string(), sh);
    }
}

nlohmann::ordered_json sh_coeffs_json(const ShCoeffs<double>& sh) {
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    for (const Vec3d& c : sh.c)
        rows.push_back(nlohmann::ordered_json::array({json_number(c.x), json_number(c.y), json_number(c.z)}));
    return rows;
}

Image contact_sheet(const SheetPanels& p) {
    const int w = p.truth.width, h = p.truth.height, gap = 2;
    Image sheet(6 * w + 5 * gap, 2 * h + gap, 3, 1.0f);
    const Image* top[6] = {&p.truth, &p.shadowed, &p.unshadowed, &p.albedo, &p.normal, &p.shadow};
    const Image err_s = abs_difference(p.shadowed, p.truth), err_u = abs_difference(p.unshadowed, p.truth);
    const Image* bottom[6] = {&p.mask, &err_s, &err_u, &p.gt_albedo, &p.gt_normal, &p.normal_error};
    const double gains[6] = {1, 4, 4, 1, 1, 1};
    for (int i = 0; i < 6; ++i) {
        const int x0 = i * (w + gap);
        for (int row = 0; row < 2; ++row)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x)
                    for (int c = 0; c < 3; ++c) sheet.at(x0 + x, row * (h + gap) + y, c) = 0.0f;
        paste(sheet, *top[i], x0, 0, w, h);
        paste(sheet, *bottom[i], x0, h + gap, w, h, gains[i]);
    }
    return sheet;
}

nlohmann::ordered_json json_number(double v) {
    return number(v);
}

nlohmann::ordered_json image_metrics_json(const ImageMetrics& m) {
    return Json{
        {"psnr", number(m.psnr)}, {"ssim", number(m.ssim)}, {"mse", number(m.mse)}, {"mae", number(m.mae)}};
}

std::string format_number(const char* printf_format, double v) {
    return fmt(printf_format, v);
}

std::string metrics_table_markdown(const std::vector<std::pair<std::string, ImageMetrics>>& rows) {
    std::string s = "| | PSNR | SSIM | MSE | MAE |\n| --- | --- | --- | --- | --- |\n";
    for (const auto& [label, m] : rows)
        s += "| " + label + " | " + fmt("%.2f", m.psnr) + " | " + fmt("%.4f", m.ssim) + " | " +
             fmt("%.5f", m.mse) + " | " + fmt("%.4f", m.mae) + " |\n";
    return s;
}

std::string contact_sheets_markdown(const std::vector<std::string>& names, const std::string& caption) {
    std::string s = "\n## Contact sheets\n\n" + caption + "\n\n";
    for (const std::string& name : names)
        s += "### " + name + "\n\n![" + name + "](" + sheet_relative_path(name) + ")\n\n";
    return s;
}

bool write_contact_sheets(const std::string& dir, const std::vector<SheetEntry>& entries, bool with_sheets) {
    bool sheets = with_sheets && !entries.empty();
    for (const SheetEntry& e : entries) sheets = sheets && e.panels && !e.panels->truth.empty();
    if (!sheets) return false;
    for (const SheetEntry& e : entries) {
        const fs::path path = fs::path(dir) / sheet_relative_path(e.name);
        fs::create_directories(path.parent_path());
        write_png(path.string(), contact_sheet(*e.panels));
    }
    return true;
}

void write_report_files(const std::string& dir, const nlohmann::ordered_json& metrics,
                        const std::string& markdown) {
    fs::create_directories(dir);
    write_file_atomically((fs::path(dir) / "metrics.json").string(), metrics.dump(2) + "\n");
    write_file_atomically((fs::path(dir) / "report.md").string(), markdown);
}

// ---- gt-env -----------------------------------------------------------------------------------------------

nlohmann::ordered_json gt_env_metrics_json(const GtEnvResult& r, const ReportSources& src) {
    Json j;
    j["protocol"] = "gt-env";
    j["run"] = src.run;
    j["scene"] = src.scene;
    j["downscale"] = r.downscale;
    j["views"] = split_name(r.views);
    if (r.views == Split::Train)
        j["views_note"] = "diagnostic: training views under their own true lights (not the protocol)";
    Json per_photo = Json::object();
    Json per_photo_direction = Json::object();
    for (std::size_t i = 0; i < r.light.per_photo.size() && i < r.light.names.size(); ++i) {
        per_photo[r.light.names[i]] = number(r.light.per_photo[i]);
        if (i < r.light.direction.size())
            per_photo_direction[r.light.names[i]] = {{"strength", number(r.light.direction[i].strength)},
                                                     {"error_deg", number(r.light.direction[i].error_deg)}};
    }
    j["light_scale"] = {
        {"value", number(r.light.scale)},
        {"method",
         "least squares of the irradiance over the sphere of normals, learned SH of the training photos vs "
         "scale * exposure * true SH (coefficients weighted by A_l^2); training photos only"},
        {"train_photos", r.light.per_photo.size()},
        {"relative_residual", number(r.light.relative_residual)},
        {"per_photo", per_photo},
        {"direction_strength", number(r.light.median_direction_strength)},
        {"direction_error_deg", number(r.light.median_direction_error_deg)},
        {"direction_method",
         "per training photo, (|band 1| / DC) of the learned SH over that of the true SH (luminance, the "
         "mean of the channels) and the angle between their band-1 vectors; medians over the photos whose "
         "true light has a direction (|band 1| >= 0.05 DC)"},
        {"per_photo_direction", per_photo_direction}};
    if (const auto& ref = r.light_reference)
        j["light_scale"]["reference"] = {
            {"method",
             "per training photo with gt/albedo and gt/normal: the light directions its normals tell apart "
             "(eigenvalues of the irradiance Gram >= 1e-3 of the largest) and the least-squares light of "
             "radiance = true albedo / pi * E(true normal) on them (cast shadows dropped); residuals as "
             "relative_residual"},
            {"photos", ref->photos},
            {"seen_directions_min", ref->min_seen},
            {"seen_directions_median", ref->median_seen},
            {"unseen_share", number(ref->unseen_share)},
            {"learned_seen_residual", number(ref->learned_seen_residual)},
            {"reference_residual", number(ref->reference_residual)},
            {"reference_seen_residual", number(ref->reference_seen_residual)}};
    j["test_exposure"] = "each test photo's meta.json exposure (its camera setting, not lighting) is applied";
    j["mask"] = r.gt_mask ? "gt/mask eroded 5x5 once, full coverage only, times the scene mask"
                          : "scene mask eroded 5x5 once, full coverage only (no gt/mask)";
    if (r.has_albedo)
        j["albedo_scale"] = {{"linear", rgb_json(r.albedo_scale)}, {"gamma", rgb_json(r.albedo_gamma_scale)}};
    Json images = Json::array();
    for (const GtEnvImageResult& im : r.images) {
        Json e;
        e["name"] = im.name;
        e["condition"] = im.condition;
        e["exposure"] = im.exposure;
        e["mask_pixels"] = im.mask_pixels;
        e["render_ms"] = im.render_ms;
        e["shadowed"] = image_metrics_json(im.shadowed);
        e["unshadowed"] = image_metrics_json(im.unshadowed);
        if (im.has_albedo)
            e["albedo"] = albedo_json(im.albedo), e["albedo_gamma"] = albedo_json(im.albedo_gamma);
        if (im.has_normal) e["normal"] = normal_json(im.normal);
        if (im.sky_pixels > 0)
            e["sky"] = {{"pixels", im.sky_pixels},
                        {"alpha_above_half", number(im.sky_alpha_fraction)},
                        {"mean_alpha", number(im.sky_mean_alpha)}};
        e["empty"] = {{"fraction", number(im.empty_fraction)},
                      {"shadowed_psnr_covered", number(im.covered_shadowed_psnr)}};
        if (r.image_scaled) e["shadowed_image_scaled"] = image_metrics_json(im.image_scaled_shadowed);
        images.push_back(std::move(e));
    }
    j["images"] = images;
    Json mean;
    mean["shadowed"] = image_metrics_json(r.mean_shadowed);
    mean["unshadowed"] = image_metrics_json(r.mean_unshadowed);
    if (r.has_albedo)
        mean["albedo"] = albedo_json(r.mean_albedo), mean["albedo_gamma"] = albedo_json(r.mean_albedo_gamma);
    if (r.has_normal) mean["normal"] = normal_json(r.mean_normal, false);
    if (r.has_normal) {
        const auto region = [&](const SurfaceRegion& g) {
            const std::size_t all = r.surfaces.up.pixels + r.surfaces.other.pixels;
            return Json{{"fraction", number(all > 0 ? double(g.pixels) / double(all) : 0.0)},
                        {"shadowed_psnr", number(g.psnr())},
                        {"gain_rgb", rgb_json({g.gain(0), g.gain(1), g.gain(2)})}};
        };
        mean["by_surface"] = {
            {"up", region(r.surfaces.up)},
            {"other", region(r.surfaces.other)},
            {"meaning",
             "evaluated pixels whose true normal is within 25 deg of +z (ground) and the others (walls, "
             "roofs), "
             "over all scored images: shadowed PSNR, and the least-squares gain per channel that takes the "
             "render onto the photo (a gain far from 1 on one kind of surface only: its albedo is off)"}};
    }
    if (r.has_sky)
        mean["sky_alpha_above_half"] = {
            {"value", number(r.sky_alpha_fraction)},
            {"meaning",
             "share of all sky pixels (gt/mask = 0) of the scored images where the render's alpha > 0.5"}};
    if (r.has_sky)
        mean["sky_mean_alpha"] = {{"value", number(r.sky_mean_alpha)},
                                  {"meaning",
                                   "mean alpha of the render over all sky pixels (gt/mask = 0) of the scored "
                                   "images: faint surfels in "
                                   "front of the camera that never reach 0.5"}};
    mean["empty"] = {
        {"fraction", number(r.empty_fraction)},
        {"shadowed_psnr_covered", number(r.mean_covered_shadowed_psnr)},
        {"meaning",
         "share of all evaluated pixels where the render's alpha <= 0.5 (no surface), and the mean "
         "shadowed PSNR over the other evaluated pixels"}};
    if (r.image_scaled) mean["shadowed_image_scaled"] = image_metrics_json(r.mean_image_scaled_shadowed);
    j["mean"] = mean;
    if (r.image_scaled)
        j["image_light_scale"] = {
            {"rgb", rgb_json(r.image_light_scale)},
            {"meaning",
             "k per channel fitted in image space on the training photos (shadowed renders under exposure "
             "* true SH against the photos); the test views are scored under it again as "
             "'shadowed_image_scaled'"}};
    j["median_render_ms"] = r.median_render_ms;
    if (r.has_normal) j["normal_all_pixels"] = normal_json(r.pooled_normal);
    return j;
}

std::string gt_env_report_markdown(const GtEnvResult& r, const ReportSources& src, bool with_sheets) {
    std::string s = "# Evaluation: gt-env\n\n";
    s += "- run: `" + src.run + "`\n- scene: `" + src.scene + "`\n";
    s += "- resolution: downscale " + std::to_string(r.downscale) + ", " + std::to_string(r.images.size()) +
         " test images\n\n";
    s += "## Protocol\n\n";
    if (r.views == Split::Train)
        s += "- **Diagnostic run on the TRAINING views** (`--cameras train`), each under its own true light; "
             "the "
             "light scale is fitted on the same photos. The protocol proper scores the test views.\n";
    s += "- Each test photo is rendered under `k * exposure * (true SH of its condition)`: no rotation "
         "search, "
         "no per-image colour fit.\n";
    s += "- `k` = " + fmt("%.6g", r.light.scale) +
         ", the one global scale between the model's light and the true light (the model's albedo/light "
         "gauge), fitted on the " +
         std::to_string(r.light.per_photo.size()) +
         " **training** photos only: least squares of the irradiance over the sphere of normals between "
         "their learned SH and `k * exposure * true SH` (SH coefficients weighted by A_l^2). Relative "
         "residual " +
         fmt("%.3f", r.light.relative_residual) + ".\n";
    if (std::isfinite(r.light.median_direction_strength))
        s +=
            "- How directional the learned lights are (training photos, median): " +
            fmt("%.2f", r.light.median_direction_strength) +
            " x the true band-1 strength (|band 1| / DC; 1 = as directional as the truth), their direction " +
            fmt("%.0f", r.light.median_direction_error_deg) + " deg from the true one.\n";
    if (const auto& ref = r.light_reference)
        s += "- What the photos can tell about their lights (" + std::to_string(ref->photos) +
             " training photos with true albedo and normals): their normals tell apart " +
             std::to_string(ref->median_seen) + " of a degree-2 light's 9 directions (median; fewest " +
             std::to_string(ref->min_seen) + "), and " + fmt("%.0f", 100 * ref->unseen_share) +
             " % of the true lights lie in the rest. On the part they see, the learned lights' residual is " +
             fmt("%.3f", ref->learned_seen_residual) +
             ". Lights fitted to the photos' shading with the TRUE albedo and normals (cast shadows dropped) "
             "reach " +
             fmt("%.3f", ref->reference_residual) + " (whole) and " +
             fmt("%.3f", ref->reference_seen_residual) +
             " (seen part): a reference for the residual above.\n";
    if (r.sky_behind) {
        s += "- The run was trained with its sky behind the surfels: renders are drawn over the condition's "
             "panorama (`env/COND.exr`; its SH where there is none) times `k * exposure`";
        const SkyHorizon& h = r.sky_horizon;
        if (h.fade_degrees > 0)
            s += ", fading out from " + fmt("%.3g", h.start_degrees) + " to " +
                 fmt("%.3g", h.start_degrees + h.fade_degrees) +
                 " deg below the horizon of the training cameras' mean up, as in training (a hole in the "
                 "ground is not filled with the true environment's lower half)";
        const Vec3f g = h.ground_albedo;
        if (h.fade_degrees > 0 && (g.x > 0 || g.y > 0 || g.z > 0))
            s += "; below it the ground the run was trained with is drawn (albedo " + fmt("%.3f", g.x) + " " +
                 fmt("%.3f", g.y) + " " + fmt("%.3f", g.z) +
                 ", the median of its surfels facing up, under the same light at the up normal)";
        s += ".\n";
    }
    s += "- The test photo's exposure (meta.json) is applied: it is the camera's setting, recorded with the "
         "photo, not lighting (1.0 for the test photos of data/plaza and `lumigauss synth`).\n";
    s += std::string("- Mask: ") +
         (r.gt_mask ? "`gt/mask` eroded once with 5x5, fully covered pixels only, times the scene's mask"
                    : "the scene's mask eroded once with 5x5 (no `gt/mask`)") +
         ".\n";
    s += "- Metrics (official): MSE = sum m (x-y)^2 / (3 sum m + 1e-6), MAE likewise, PSNR = -10 log10(MSE + "
         "1e-6), SSIM = skimage `structural_similarity` (5x5 uniform window, sample covariance, data range "
         "1) averaged over the mask; renders clamped to [0, 1]; means are over images (PSNR averaged as "
         "PSNR).\n";
    if (r.has_albedo)
        s += "- Albedo: the model's albedo rasterised; *linear* = albedo^2.2 vs `gt/albedo`, *gamma* = "
             "albedo vs "
             "`gt/albedo`^(1/2.2), each after one per-channel least-squares scale over all test images "
             "(linear " +
             fmt("%.4g", r.albedo_scale[0]) + " " + fmt("%.4g", r.albedo_scale[1]) + " " +
             fmt("%.4g", r.albedo_scale[2]) + ", gamma " + fmt("%.4g", r.albedo_gamma_scale[0]) + " " +
             fmt("%.4g", r.albedo_gamma_scale[1]) + " " + fmt("%.4g", r.albedo_gamma_scale[2]) + ").\n";
    if (r.has_normal)
        s += "- Normals: rendered world normals vs `gt/normal` on the mask; a pixel with nothing rendered "
             "counts "
             "as 90 deg.\n";
    s += "\n## Summary (mean over test images)\n\n";
    s += metrics_table_markdown({{"shadowed", r.mean_shadowed}, {"unshadowed", r.mean_unshadowed}});
    if (r.has_albedo) {
        s += "| albedo (linear) | " + fmt("%.2f", r.mean_albedo.psnr) + " | | " +
             fmt("%.5f", r.mean_albedo.mse) + " | " + fmt("%.4f", r.mean_albedo.mae) + " |\n";
        s += "| albedo (gamma) | " + fmt("%.2f", r.mean_albedo_gamma.psnr) + " | | " +
             fmt("%.5f", r.mean_albedo_gamma.mse) + " | " + fmt("%.4f", r.mean_albedo_gamma.mae) + " |\n";
    }
    if (r.has_normal)
        s += "\nNormal angular error: mean " + fmt("%.2f", r.mean_normal.mean_deg) + " deg, median " +
             fmt("%.2f", r.mean_normal.median_deg) +
             " deg (means of the per-image values); over all pixels: mean " +
             fmt("%.2f", r.pooled_normal.mean_deg) + ", median " + fmt("%.2f", r.pooled_normal.median_deg) +
             " deg.\n";
    if (r.image_scaled)
        s += "\nUnder the light scale fitted per channel on the training images (k = " +
             fmt("%.4g", r.image_light_scale[0]) + " " + fmt("%.4g", r.image_light_scale[1]) + " " +
             fmt("%.4g", r.image_light_scale[2]) +
             "; it follows the model's colour gauge and ignores light "
             "no photo constrains): shadowed PSNR " +
             fmt("%.2f", r.mean_image_scaled_shadowed.psnr) + " dB, SSIM " +
             fmt("%.4f", r.mean_image_scaled_shadowed.ssim) + ".\n";
    if (r.has_normal) {
        const auto gains = [&](const SurfaceRegion& g) {
            return fmt("%.3f", g.gain(0)) + " " + fmt("%.3f", g.gain(1)) + " " + fmt("%.3f", g.gain(2));
        };
        s += "\nBy surface (true normal within 25 deg of up, or not): shadowed PSNR facing up " +
             fmt("%.2f", r.surfaces.up.psnr()) + " dB (gain to the photos " + gains(r.surfaces.up) +
             "), the rest " + fmt("%.2f", r.surfaces.other.psnr()) + " dB (gain " + gains(r.surfaces.other) +
             ").\n";
    }
    s += "\nEvaluated pixels the model leaves empty (alpha <= 0.5): " + fmt("%.2f", 100 * r.empty_fraction) +
         " %; shadowed PSNR over the covered ones " + fmt("%.2f", r.mean_covered_shadowed_psnr) + " dB.\n";
    if (r.has_sky)
        s += "\nSky pixels (`gt/mask` = 0) covered by surfels (alpha > 0.5): " +
             fmt("%.2f", 100 * r.sky_alpha_fraction) + " %; mean alpha over the sky " +
             fmt("%.4f", r.sky_mean_alpha) + ".\n";
    s += "\n## Per image\n\n| image | condition | exposure | PSNR sh. | SSIM sh. | PSNR unsh. | SSIM unsh. | "
         "albedo PSNR | normal mean / median |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
    for (const GtEnvImageResult& im : r.images)
        s += "| " + im.name + " | " + im.condition + " | " + fmt("%.3f", im.exposure) + " | " +
             fmt("%.2f", im.shadowed.psnr) + " | " + fmt("%.4f", im.shadowed.ssim) + " | " +
             fmt("%.2f", im.unshadowed.psnr) + " | " + fmt("%.4f", im.unshadowed.ssim) + " | " +
             (im.has_albedo ? fmt("%.2f", im.albedo.psnr) : "n/a") + " | " +
             (im.has_normal ? fmt("%.1f", im.normal.mean_deg) + " / " + fmt("%.1f", im.normal.median_deg)
                            : "n/a") +
             " |\n";
    if (with_sheets) {
        std::vector<std::string> names;
        for (const GtEnvImageResult& im : r.images) names.push_back(im.name);
        s += contact_sheets_markdown(names,
                                     "Top: photo | shadowed | unshadowed | albedo | normals | shadow "
                                     "(shadowed / unshadowed). Bottom: mask | shadowed error x4 | unshadowed "
                                     "error x4 | ground-truth albedo | ground-truth normals | normal error "
                                     "(white = 45 deg or more).");
    }
    return s;
}

Image gt_env_contact_sheet(const GtEnvImageResult& im) {
    return contact_sheet(im.panels);
}

void write_gt_env_report(const std::string& dir, const GtEnvResult& result, const ReportSources& sources,
                         bool with_sheets) {
    std::vector<SheetEntry> entries;
    for (const GtEnvImageResult& im : result.images) entries.push_back({im.name, &im.panels});
    const bool sheets = write_contact_sheets(dir, entries, with_sheets);
    write_report_files(dir, gt_env_metrics_json(result, sources),
                       gt_env_report_markdown(result, sources, sheets));
}

}  // namespace lumigauss
