#include "lumigauss/eval/sol_nerf_report.h"

#include <nlohmann/json.hpp>
#include <numbers>

namespace lumigauss {
namespace {

using Json = nlohmann::ordered_json;

double degrees(double radians) {
    return radians * 180.0 / std::numbers::pi;
}

Json image_json(const SolNerfImageResult& im) {
    Json e;
    e["name"] = im.config.name;
    e["view"] = im.view_name;
    e["split"] = split_name(im.split);
    e["env_map"] = im.env_map_path;
    e["mask_file"] = im.mask_path.empty() ? Json(nullptr) : Json(im.mask_path);
    e["mask_pixels"] = im.mask_pixels;
    e["hdr"] = {{"threshold", json_number(im.config.hdr_threshold)},
                {"scale", json_number(im.config.hdr_scale)},
                {"boosted_values", im.boosted_values}};
    e["rotation_deg"] = {
        {"x", im.config.rotation_deg[0]}, {"y", im.config.rotation_deg[1]}, {"z", im.config.rotation_deg[2]}};
    e["y_range_rad"] = Json::array({json_number(im.config.y_min), json_number(im.config.y_max)});
    e["best_angle_rad"] = json_number(im.best_angle);
    e["best_angle_deg"] = json_number(degrees(im.best_angle));
    e["best_index"] = im.best_index;
    e["best_at_range_edge"] = im.best_at_range_edge();
    Json psnr = Json::array();
    for (double v : im.search_psnr) psnr.push_back(json_number(v));
    e["search_psnr"] = psnr;
    e["environment_sh"] = sh_coeffs_json(im.world_sh);
    e["shadowed"] = image_metrics_json(im.shadowed);
    e["unshadowed"] = image_metrics_json(im.unshadowed);
    e["search_ms"] = im.search_ms;
    e["render_ms"] = im.render_ms;
    return e;
}

std::string protocol_markdown(const SolNerfResult& r) {
    std::string s = "## Protocol\n\n";
    s += "- SOL-NeRF, as the official LumiGauss `test_gt_env_map.py`: each test photo's ground-truth "
         "panorama -> /255 (no linearisation) -> fake HDR (every channel value above the threshold times the "
         "scale) -> 1000x500 bicubic if wider -> degree-2 SH by the official projection (Chalmers' "
         "`getCoefficientsFromImage`, its frame and pixel weights) -> fixed rotation rot_y(y0) rot_x(x0) "
         "rot_z(z0) -> rot_y(b) for " +
         std::to_string(r.angles) + " angles b = linspace(first, last) of the configured range.\n";
    s += "- For each b the **shadowed** render, clamped to [0, 1], is scored by its masked PSNR against the "
         "photo, and the first best b is kept: an oracle search on the test photo itself, as in SOL-NeRF. "
         "The shadowed and unshadowed metrics are both taken at that b. No per-image colour or exposure fit; "
         "the run's learned lighting is not used.\n";
    s +=
        "- Mask: the configured evaluation mask resized bilinearly to the photo, eroded once with 5x5, fully "
        "covered pixels only (the scene's own mask the same way where none is configured).\n";
    s += "- Metrics (official): MSE = sum m (x-y)^2 / (3 sum m + 1e-6), MAE likewise, PSNR = -10 log10(MSE + "
         "1e-6), SSIM = skimage `structural_similarity` (5x5 uniform window, sample covariance, data range "
         "1) averaged over the mask; means are over images (PSNR averaged as PSNR).\n";
    s +=
        "- `env/NAME_sh.txt`: the world-frame SH each photo was scored under (`lumigauss render --light`).\n";
    return s;
}

std::string per_image_markdown(const SolNerfResult& r) {
    std::string s =
        "\n## Per image\n\n| image | split | best angle (deg) | range (deg) | PSNR sh. | SSIM sh. | "
        "PSNR unsh. | SSIM unsh. | mask pixels |\n| --- | --- | --- | --- | --- | --- | --- | --- | "
        "--- |\n";
    std::string edges;
    for (const SolNerfImageResult& im : r.images) {
        s += "| " + im.config.name + " | " + split_name(im.split) + " | " +
             format_number("%.1f", degrees(im.best_angle)) + " | " +
             format_number("%.1f", degrees(im.config.y_min)) + " .. " +
             format_number("%.1f", degrees(im.config.y_max)) + " | " +
             format_number("%.2f", im.shadowed.psnr) + " | " + format_number("%.4f", im.shadowed.ssim) +
             " | " + format_number("%.2f", im.unshadowed.psnr) + " | " +
             format_number("%.4f", im.unshadowed.ssim) + " | " + std::to_string(im.mask_pixels) +
             (im.mask_path.empty() ? " (scene mask)" : "") + " |\n";
        if (im.best_at_range_edge()) edges += (edges.empty() ? "" : ", ") + im.config.name;
    }
    if (!edges.empty())
        s += "\n**Note:** the best angle lies at an end of the configured range for " + edges +
             ": the true orientation may lie outside it (the ranges were tuned for the official COLMAP "
             "reconstruction).\n";
    return s;
}

}  // namespace

nlohmann::ordered_json sol_nerf_metrics_json(const SolNerfResult& r, const ReportSources& src) {
    Json j;
    j["protocol"] = "sol-nerf";
    j["run"] = src.run;
    j["scene"] = src.scene;
    j["config"] = r.config_path;
    j["downscale"] = r.downscale;
    j["angles"] = r.angles;
    j["mask"] = "evaluation mask resized bilinearly to the photo, eroded 5x5 once, full coverage only";
    j["environment"] =
        "official projection of the fake-HDR panorama, rot_y(b) rot_y(y0) rot_x(x0) rot_z(z0); b = the best "
        "of the search by shadowed masked PSNR";
    Json images = Json::array();
    for (const SolNerfImageResult& im : r.images) images.push_back(image_json(im));
    j["images"] = images;
    j["mean"] = {{"shadowed", image_metrics_json(r.mean_shadowed)},
                 {"unshadowed", image_metrics_json(r.mean_unshadowed)}};
    j["median_render_ms"] = r.median_render_ms;
    j["search_seconds"] = r.search_seconds;
    return j;
}

std::string sol_nerf_report_markdown(const SolNerfResult& r, const ReportSources& src, bool with_sheets) {
    std::string s = "# Evaluation: sol-nerf\n\n";
    s += "- run: `" + src.run + "`\n- scene: `" + src.scene + "`\n- config: `" + r.config_path + "`\n";
    s += "- resolution: downscale " + std::to_string(r.downscale) + ", " + std::to_string(r.images.size()) +
         " test images\n\n";
    s += protocol_markdown(r);
    s += "\n## Summary (mean over test images)\n\n";
    s += metrics_table_markdown({{"shadowed", r.mean_shadowed}, {"unshadowed", r.mean_unshadowed}});
    s += per_image_markdown(r);
    if (with_sheets) {
        std::vector<std::string> names;
        for (const SolNerfImageResult& im : r.images) names.push_back(im.config.name);
        s += contact_sheets_markdown(
            names,
            "Top: photo | shadowed | unshadowed | albedo | normals | shadow "
            "(shadowed / unshadowed), all at the chosen angle. Bottom: mask | shadowed "
            "error x4 | unshadowed error x4 (the rest is black: NeRF-OSR has no "
            "ground-truth albedo or normals).");
    }
    return s;
}

void write_sol_nerf_report(const std::string& dir, const SolNerfResult& result, const ReportSources& sources,
                           bool with_sheets) {
    std::vector<SheetEntry> entries;
    for (const SolNerfImageResult& im : result.images) entries.push_back({im.config.name, &im.panels});
    const bool sheets = write_contact_sheets(dir, entries, with_sheets);
    std::vector<std::pair<std::string, ShCoeffs<double>>> lights;
    for (const SolNerfImageResult& im : result.images) lights.emplace_back(im.config.name, im.world_sh);
    write_scored_lights(dir, lights);
    write_report_files(dir, sol_nerf_metrics_json(result, sources),
                       sol_nerf_report_markdown(result, sources, sheets));
}

}  // namespace lumigauss
