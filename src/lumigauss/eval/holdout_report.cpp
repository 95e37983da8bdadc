#include "lumigauss/eval/holdout_report.h"

#include <filesystem>
#include <nlohmann/json.hpp>

namespace lumigauss {
namespace {

using Json = nlohmann::ordered_json;

Json image_json(const HoldoutImageResult& im) {
    Json e;
    e["name"] = im.name;
    e["fit_pixels"] = im.fit_pixels;
    e["score_pixels"] = im.score_pixels;
    e["fit_psnr"] = {{"shadowed", json_number(im.fit_psnr)},
                     {"unshadowed", json_number(im.fit_psnr_unshadowed)}};
    e["fit_ms"] = im.fit_ms;
    e["render_ms"] = im.render_ms;
    e["environment_sh"] = {{"shadowed", sh_coeffs_json(im.light)},
                           {"unshadowed", sh_coeffs_json(im.light_unshadowed)}};
    e["shadowed"] = image_metrics_json(im.shadowed);
    e["unshadowed"] = image_metrics_json(im.unshadowed);
    return e;
}

std::string protocol_markdown(const HoldoutResult& r) {
    const std::string variable = r.variable == LightVariable::Sh
                                     ? "the 27 environment SH coefficients"
                                     : "a new embedding through the run's lighting network";
    std::string s = "## Protocol\n\n";
    s += "- Holdout (NeRF-W style, for photos without ground-truth lighting): the lighting of each photo is "
         "fitted with the model frozen (`lumigauss fit-light`: Adam on " +
         variable + ", " + std::to_string(r.iterations) +
         " iterations, the training objective 0.8 L1 + 0.2 D-SSIM of the render plus l_+) on the "
         "**left half** of the photo (columns x < W/2, weighted by the scene's mask), once for the shadowed "
         "and once for the unshadowed render.\n";
    s += "- The render under that light is scored on the **right half** (x >= W/2), which the fit never saw: "
         "the scene's mask binarised at 0.5, eroded once with 5x5, fully covered pixels only. Each render is "
         "scored under its own fitted light.\n";
    s += "- Metrics (official): MSE = sum m (x-y)^2 / (3 sum m + 1e-6), MAE likewise, PSNR = -10 log10(MSE + "
         "1e-6), SSIM = skimage `structural_similarity` (5x5 uniform window) averaged over the mask; means "
         "are "
         "over images (PSNR averaged as PSNR).\n";
    s += "- `env/NAME_sh.txt`, `env/NAME_unshadowed_sh.txt`: the fitted lights of each photo (`lumigauss "
         "render --light`).\n";
    return s;
}

std::string per_image_markdown(const HoldoutResult& r) {
    std::string s =
        "\n## Per image\n\n| image | fit PSNR sh. / unsh. (left) | PSNR sh. | SSIM sh. | PSNR unsh. | SSIM "
        "unsh. | "
        "score pixels |\n| --- | --- | --- | --- | --- | --- | --- |\n";
    for (const HoldoutImageResult& im : r.images)
        s += "| " + im.name + " | " + format_number("%.2f", im.fit_psnr) + " / " +
             format_number("%.2f", im.fit_psnr_unshadowed) + " | " + format_number("%.2f", im.shadowed.psnr) +
             " | " + format_number("%.4f", im.shadowed.ssim) + " | " +
             format_number("%.2f", im.unshadowed.psnr) + " | " + format_number("%.4f", im.unshadowed.ssim) +
             " | " + std::to_string(im.score_pixels) + " |\n";
    return s;
}

}  // namespace

nlohmann::ordered_json holdout_metrics_json(const HoldoutResult& r, const ReportSources& src, int downscale) {
    Json j;
    j["protocol"] = "holdout";
    j["run"] = src.run;
    j["scene"] = src.scene;
    j["downscale"] = downscale;
    j["views"] = split_name(r.views);
    j["fit"] = {{"variable", light_variable_name(r.variable)},
                {"iterations", r.iterations},
                {"renders", "each of shadowed and unshadowed fitted and scored on its own"},
                {"fit_mask", "scene mask (soft) on columns x < W/2"},
                {"score_mask", "scene mask > 0.5, eroded 5x5 once, full coverage only, on columns x >= W/2"}};
    Json images = Json::array();
    for (const HoldoutImageResult& im : r.images) images.push_back(image_json(im));
    j["images"] = images;
    j["mean"] = {{"shadowed", image_metrics_json(r.mean_shadowed)},
                 {"unshadowed", image_metrics_json(r.mean_unshadowed)},
                 {"fit_psnr",
                  {{"shadowed", json_number(r.mean_fit_psnr)},
                   {"unshadowed", json_number(r.mean_fit_psnr_unshadowed)}}}};
    j["median_fit_ms"] = r.median_fit_ms;
    j["median_render_ms"] = r.median_render_ms;
    return j;
}

std::string holdout_report_markdown(const HoldoutResult& r, const ReportSources& src, int downscale,
                                    bool with_sheets) {
    std::string s = "# Evaluation: holdout\n\n";
    s += "- run: `" + src.run + "`\n- scene: `" + src.scene + "`\n";
    s += "- resolution: downscale " + std::to_string(downscale) + ", " + std::to_string(r.images.size()) +
         " " + split_name(r.views) + " images\n\n";
    s += protocol_markdown(r);
    s += "\n## Summary (mean over images, right halves)\n\n";
    s += metrics_table_markdown({{"shadowed", r.mean_shadowed}, {"unshadowed", r.mean_unshadowed}});
    s += "\nMean fit PSNR on the left halves: shadowed " + format_number("%.2f", r.mean_fit_psnr) +
         " dB, unshadowed " + format_number("%.2f", r.mean_fit_psnr_unshadowed) + " dB.\n";
    s += per_image_markdown(r);
    if (with_sheets) {
        std::vector<std::string> names;
        for (const HoldoutImageResult& im : r.images) names.push_back(im.name);
        s += contact_sheets_markdown(
            names,
            "Top: photo | shadowed | unshadowed | albedo | normals | shadow, under the "
            "light fitted on the left half. Bottom: score mask (right half) | shadowed "
            "error x4 | unshadowed error x4 (the rest is black: no ground truth).");
    }
    return s;
}

void write_holdout_report(const std::string& dir, const HoldoutResult& result, const ReportSources& sources,
                          int downscale, bool with_sheets) {
    std::vector<SheetEntry> entries;
    std::vector<std::pair<std::string, ShCoeffs<double>>> lights;
    for (const HoldoutImageResult& im : result.images) {
        entries.push_back({im.name, &im.panels});
        lights.emplace_back(im.name, im.light);
        std::filesystem::path unshadowed(im.name);
        unshadowed.replace_extension();
        lights.emplace_back(unshadowed.string() + "_unshadowed", im.light_unshadowed);
    }
    const bool sheets = write_contact_sheets(dir, entries, with_sheets);
    write_scored_lights(dir, lights);
    write_report_files(dir, holdout_metrics_json(result, sources, downscale),
                       holdout_report_markdown(result, sources, downscale, sheets));
}

}  // namespace lumigauss
